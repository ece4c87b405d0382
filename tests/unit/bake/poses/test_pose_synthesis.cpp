// Pose synthesis (part1.synthesis): a redrawn joint takes rotations between (and a little beyond) two
// recorded samples' while every other joint keeps the base sample's; the thinning adds the candidates
// that cover what the recorded poses leave empty; deterministic for a seed; bad joints are errors.
#include <gtest/gtest.h>

#include <cmath>

#include "support/random_model.hpp"
#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/bake/poses/pose_synthesis.hpp"
#include "swish/bake/poses/pose_thinning.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

Skeleton smallSkeleton() {
  Skeleton s;
  auto add = [&](const char* n, int parent, Vec3f t) { s.joints.push_back({n, parent, {Quatf::Identity(), t}}); };
  add("Hips", -1, {0, 1, 0});
  add("Spine", 0, {0, 0.2f, 0});
  add("LeftShoulder", 1, {0.05f, 0.2f, 0});
  add("LeftArm", 2, {0.15f, 0, 0});
  s.computeInverseBindFromRest();
  return s;
}

float angleBetween(const Quatf& a, const Quatf& b) { return float(a.angularDistance(b)); }

// Two "subjects": the clavicle (LeftShoulder) fixed per clip at 10 and 40 degrees about z, the spine
// and arm moving as mocap does.
std::vector<AnimationClip> twoSubjects(const Skeleton& s) {
  std::vector<AnimationClip> clips;
  for (float clavicleDegrees : {10.f, 40.f}) {
    AnimationClip c;
    c.name = "subject";
    c.framesPerSecond = 30.f;
    Rng rng(test::testSeed(uint64_t(clavicleDegrees)));
    for (int f = 0; f < 60; ++f) {
      Pose p = s.restPose();
      p.local[1] = Quatf(Eigen::AngleAxisf(float(rng.uniform(-0.4, 0.4)), Vec3f::UnitX()));
      p.local[2] = Quatf(Eigen::AngleAxisf(clavicleDegrees * float(M_PI) / 180.f, Vec3f::UnitZ()));
      p.local[3] = Quatf(Eigen::AngleAxisf(float(rng.uniform(-1.2, 0.3)), Vec3f::UnitZ()));
      c.frames.push_back(p);
    }
    clips.push_back(c);
  }
  return clips;
}

}  // namespace

TEST(PoseSynthesis, RotationBetweenFollowsTheShortestArcAndExtrapolates) {
  const Quatf a(Eigen::AngleAxisf(0.3f, Vec3f(1, 2, 3).normalized()));
  const Quatf b = a * Quatf(Eigen::AngleAxisf(0.8f, Vec3f::UnitY()));
  EXPECT_LT(angleBetween(rotationBetween(a, b, 0.f), a), 1e-5f);
  EXPECT_LT(angleBetween(rotationBetween(a, b, 1.f), b), 1e-5f);
  EXPECT_NEAR(angleBetween(rotationBetween(a, b, 0.5f), a), 0.4f, 1e-4f);
  EXPECT_NEAR(angleBetween(rotationBetween(a, b, 1.25f), a), 1.0f, 1e-4f);  // past b, on the same arc
  EXPECT_NEAR(angleBetween(rotationBetween(a, b, 1.25f), b), 0.2f, 1e-4f);
  EXPECT_NEAR(angleBetween(rotationBetween(a, b, -0.25f), a), 0.2f, 1e-4f);  // away from b
  EXPECT_NEAR(angleBetween(rotationBetween(a, b, -0.25f), b), 1.0f, 1e-4f);
  const Quatf minusB(-b.w(), -b.x(), -b.y(), -b.z());  // the same rotation: the same arc
  EXPECT_LT(angleBetween(rotationBetween(a, minusB, 0.5f), rotationBetween(a, b, 0.5f)), 1e-5f);
}

TEST(PoseSynthesis, ARedrawnJointFillsTheGapBetweenSubjectsAndTheRestStaysRecorded) {
  const Skeleton s = smallSkeleton();
  const std::vector<AnimationClip> clips = twoSubjects(s);
  PoseSamplingOptions so;
  so.joints = {"Spine", "LeftShoulder", "LeftArm"};
  so.characters = 1;
  so.mirrorOddCharacters = false;
  so.speedJitter = 0.f;
  const PoseSamples samples = samplePoses(s, clips, so);
  const ThinningResult recorded = thinPosesToCount(samples, 30);
  const std::vector<uint32_t> theta{1, 2, 3};

  PoseSynthesisSettings ps;
  ps.joints = {"LeftShoulder"};
  ps.poses = 20;
  ps.extend = 0.25f;
  ps.seed = 7;
  const SynthesisResult r = synthesizePoses(s, clips, samples, recorded.kept, theta, ps);
  EXPECT_EQ(r.candidates, 160u);  // 8 per pose asked
  EXPECT_NEAR(double(r.added.size()), 20.0, 0.03 * 50.0);
  ASSERT_FALSE(r.added.empty());

  // Recorded clavicles: 10 and 40 degrees only. Synthesized: anywhere from 10 - 0.25 * 30 to
  // 40 + 0.25 * 30 degrees, and the thinning prefers the ones between, which no recorded pose covers.
  size_t between = 0;
  for (const SynthesizedPose& sp : r.added) {
    ASSERT_EQ(sp.draws.size(), 1u);
    EXPECT_EQ(sp.draws[0].joint, 2u);
    EXPECT_GE(sp.draws[0].t, -0.25f);
    EXPECT_LE(sp.draws[0].t, 1.25f);
    const Pose p = poseOfSynthesized(s, clips, sp), base = poseOfSample(s, clips, sp.base);
    const float deg = 2.f * std::acos(std::min(1.f, std::abs(p.local[2].w()))) * 180.f / float(M_PI);
    EXPECT_GE(deg, 10.f - 7.5f - 1e-3f);
    EXPECT_LE(deg, 40.f + 7.5f + 1e-3f);
    between += deg > 12.f && deg < 38.f;
    for (size_t j : {0u, 1u, 3u}) EXPECT_LT(angleBetween(p.local[j], base.local[j]), 1e-6f) << "joint " << j;
  }
  EXPECT_GT(between, r.added.size() / 2);

  // Deterministic for a seed; another seed draws other poses.
  const SynthesisResult again = synthesizePoses(s, clips, samples, recorded.kept, theta, ps);
  ASSERT_EQ(again.added.size(), r.added.size());
  for (size_t i = 0; i < r.added.size(); ++i) EXPECT_EQ(again.added[i].draws[0].t, r.added[i].draws[0].t);
  ps.seed = 8;
  const SynthesisResult other = synthesizePoses(s, clips, samples, recorded.kept, theta, ps);
  EXPECT_NE(other.added[0].draws[0].t, r.added[0].draws[0].t);

  // Off without joints or poses; errors name the setting.
  EXPECT_TRUE(synthesizePoses(s, clips, samples, recorded.kept, theta, PoseSynthesisSettings{}).added.empty());
  ps.joints = {"LeftClavicle"};
  try {
    synthesizePoses(s, clips, samples, recorded.kept, theta, ps);
    ADD_FAILURE() << "an unknown joint was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("part1.synthesis.joints: joint 'LeftClavicle'"), std::string::npos)
        << e.what();
  }
  ps.joints = {"LeftShoulder"};
  ps.extend = 2.f;
  EXPECT_THROW(synthesizePoses(s, clips, samples, recorded.kept, theta, ps), Error);
}
