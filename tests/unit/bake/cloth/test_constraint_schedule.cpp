// The cloth solver's constraint sweep in dependency levels (constraint_schedule.hpp): the levels keep
// every pair of constraints that share a vertex in the sweep's order, and the scheduled sweep, scalar
// or AVX2, gives bitwise the sequential sweep's positions, in a bare sweep and in a whole pose's solve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "support/cloth_fixture.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/cloth/constraint_schedule.hpp"
#include "swish/bake/cloth/simulation_mesh.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

bool sameBits(const Points3f& a, const Points3f& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(float) * size_t(a.size())) == 0;
}

// The tube of the capsule character at its simulation resolution, its rest shape jittered by up to
// `jitter` m per coordinate so that every constraint has something to correct (stretch and
// compression both, so both compliances and the multiplier's reset run).
struct Jittered {
  ClothConstraints cc;
  Points3f x;
};
Jittered jitteredTube(float jitter, uint64_t seed) {
  const Character ch = test::capsuleCharacter();
  const SimulationMesh mesh = buildSimulationMesh(ch, 3000);
  Jittered j;
  j.cc = buildClothConstraints(mesh, mesh.restPositions, clothMaterialPreset("jersey"));
  j.x = mesh.restPositions;
  Rng rng(seed);
  for (Eigen::Index k = 0; k < j.x.size(); ++k) j.x.data()[k] += rng.uniformf(-jitter, jitter);
  return j;
}

}  // namespace

TEST(ConstraintSchedule, LevelsKeepTheOrderOfConstraintsThatShareAVertex) {
  // A chain 0-1-2-3 visited in order, then an edge 0-3 and one 4-5 that touches nothing before it.
  const uint32_t v[] = {0, 1, 1, 2, 2, 3, 0, 3, 4, 5};
  const std::vector<uint32_t> level = dependencyLevels(6, 5, 2, v);
  EXPECT_EQ(level, (std::vector<uint32_t>{0, 1, 2, 3, 0}));

  // On a real mesh: no two constraints of a level share a vertex, and of two that do, the earlier one
  // in the sweep has the lower level.
  const Jittered t = jitteredTube(0.f, 1);
  std::vector<uint32_t> verts;
  for (const DistanceConstraint& c : t.cc.stretch) verts.insert(verts.end(), {c.i, c.j});
  const std::vector<uint32_t> lv = dependencyLevels(size_t(t.x.rows()), t.cc.stretch.size(), 2, verts.data());
  std::vector<std::vector<size_t>> byVertex(size_t(t.x.rows()));
  for (size_t k = 0; k < t.cc.stretch.size(); ++k)
    for (uint32_t u : {t.cc.stretch[k].i, t.cc.stretch[k].j}) byVertex[u].push_back(k);
  size_t pairs = 0;
  for (const std::vector<size_t>& ks : byVertex)
    for (size_t a = 0; a + 1 < ks.size(); ++a) {
      ASSERT_LT(lv[ks[a]], lv[ks[a + 1]]) << "constraints " << ks[a] << " and " << ks[a + 1];
      ++pairs;
    }
  EXPECT_GT(pairs, t.cc.stretch.size());  // the mesh's constraints do share vertices: the check ran

  // The levels are wide enough for eight lanes: most constraints run vectorised where AVX2 is there.
  const ConstraintSchedule s = buildConstraintSchedule(t.cc);
  EXPECT_EQ(s.total(), t.cc.stretch.size() + t.cc.shear.size() + t.cc.bending.size());
  std::printf("stretch: %zu constraints in %zu levels; shear %zu in %zu; bending %zu in %zu; vectorised %zu of %zu\n",
              s.stretch.constraints.size(), s.stretch.levelStart.size() - 1, s.shear.constraints.size(),
              s.shear.levelStart.size() - 1, s.bending.constraints.size(), s.bending.levelStart.size() - 1,
              s.vectorised(), s.total());
  if (constraintSweepVectorised()) {
    EXPECT_GT(s.vectorised(), s.total() * 8 / 10);
  }
}

TEST(ConstraintSchedule, ScheduledSweepsGiveTheSequentialSweepsBits) {
  const Jittered t = jitteredTube(0.004f, 7);
  const ClothConstraints& cc = t.cc;
  const ConstraintSchedule s = buildConstraintSchedule(cc);
  const float* w = cc.inverseMass.data();
  const float invDt2 = 360.f * 360.f;
  const size_t n = cc.stretch.size() + cc.shear.size() + cc.bending.size();
  // Three sweeps with the multipliers carried (as the solver's sweeps within one substep).
  Points3f seq = t.x;
  std::vector<float> lseq(n, 0.f);
  for (int it = 0; it < 3; ++it) {
    float* l = lseq.data();
    for (const DistanceConstraint& c : cc.stretch) projectDistance(c, seq.data(), w, invDt2, *l++);
    for (const ShearConstraint& c : cc.shear) projectShear(c, seq.data(), w, invDt2, *l++);
    for (const DistanceConstraint& c : cc.bending) projectDistance(c, seq.data(), w, invDt2, *l++);
  }
  ASSERT_FALSE(sameBits(seq, t.x));  // the sweeps moved the jittered tube
  for (bool vector : {false, true}) {
    Points3f x = t.x;
    std::vector<float> lambda(n, 0.f);
    for (int it = 0; it < 3; ++it) {
      s.sweep(x.data(), invDt2, lambda.data(), vector);
    }
    EXPECT_TRUE(sameBits(x, seq)) << (vector ? "AVX2" : "scalar") << " levels differ from the sequential sweep";
    // The multipliers are the same numbers, in the schedule's order: compare them as multisets.
    std::vector<float> a = lambda, b = lseq;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_TRUE(a == b) << (vector ? "AVX2" : "scalar") << " multipliers differ";
  }
}

namespace {

// One pose solved with each kernel: positions, residuals and fingerprints bitwise the same.
void expectEveryKernelSolvesTheSame(const Character& ch, size_t vertices, const Pose& pose, ClothSimSettings settings) {
  PoseSimulation results[3];
  const SweepKernel kernels[3] = {SweepKernel::Sequential, SweepKernel::Levels, SweepKernel::Vector};
  uint64_t fingerprints[3];
  for (int k = 0; k < 3; ++k) {
    settings.sweepKernel = kernels[k];
    const ClothSolver solver(ch, buildSimulationMesh(ch, vertices), settings);
    results[k] = solver.simulate(pose);
    fingerprints[k] = solver.fingerprint();
    ASSERT_TRUE(results[k].ok) << results[k].failure;
  }
  for (int k = 1; k < 3; ++k) {
    EXPECT_TRUE(sameBits(results[k].positions, results[0].positions)) << ch.name << ", kernel " << k;
    EXPECT_EQ(results[k].residuals.equilibriumResidual, results[0].residuals.equilibriumResidual);
    EXPECT_EQ(results[k].residuals.equilibriumFrames, results[0].residuals.equilibriumFrames);
    EXPECT_EQ(fingerprints[k], fingerprints[0]);  // cached poses of either kernel are the same poses
  }
}

}  // namespace

TEST(ConstraintSchedule, ASolvedPoseIsBitwiseTheSameWithEveryKernel) {
  ClothSimSettings settings;
  settings.transitionSeconds = 0.5f;
  settings.settleSeconds = 0.25f;
  settings.equilibriumSeconds = 0.25f;
  const Character capsule = test::capsuleCharacter();
  Pose bent = capsule.skeleton.restPose();
  bent.local[2] = Quatf(Eigen::AngleAxisf(0.7f, Vec3f(1.f, 0.f, 0.3f).normalized()));
  expectEveryKernelSolvesTheSame(capsule, 3000, bent, settings);

  // The default mannequin (separate body parts, the band anchored to the trunk, two contact planes in
  // the armpits), coarse: the spine bent and twisted, an arm raised.
  const Character mannequin = makeDefaultCharacter();
  Pose pose = mannequin.skeleton.restPose();
  for (const char* name : {"LowerBack", "Spine", "Spine1"})
    pose.local[size_t(mannequin.skeleton.find(name))] =
        Quatf(Eigen::AngleAxisf(0.2f, Vec3f(0.6f, 0.5f, 0.2f).normalized()));
  pose.local[size_t(mannequin.skeleton.find("LeftArm"))] = Quatf(Eigen::AngleAxisf(0.6f, Vec3f::UnitZ()));
  settings.attachTopFraction = 0.03f;  // the default bake's band
  expectEveryKernelSolvesTheSame(mannequin, 2000, pose, settings);
}
