// Time per pose of the source cloth simulation at the default resolution (~12,000 simulation
// vertices), one pose per iteration on one thread (the bake runs one pose per core): the transition,
// the settle and the equilibrium phase, and any retry. The budget:
// 700 poses in 30 minutes on 2 cores = about 5 core-seconds per pose.
//
// Characters: the shared CC0 test character (../shared/assets/tshirt_lo.glb, a 902-vertex shirt
// subdivided to ~12.9k) when present, the default mannequin's jersey at the default bake's resolution
// and band (6000 simulation vertices, attach band 0.03: assets/default/bake.json), and the capsule
// torso with a 3,000-vertex tube.
//
// The argument is the sweep kernel (cloth_solver.hpp SweepKernel: 0 sequential, 1 dependency levels one
// at a time, 2 levels eight at a time with AVX2, the default): all three give bitwise the same shapes
// (test_constraint_schedule.cpp), so their ratio is the kernel's speed-up and nothing else. The
// counter `vectorised_share` is the share of the constraints that ran in vector lanes.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "support/cloth_fixture.hpp"
#include "support/paths.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/io/character_import.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

// Bends and twists of the spine and arms that the thinned pose sets are made of.
std::vector<Pose> benchPoses(const Skeleton& sk) {
  std::vector<Pose> poses;
  const char* spine[] = {"LowerBack", "Spine", "Spine1"};
  for (int i = 0; i < 4; ++i) {
    Pose p = sk.restPose();
    const Vec3f axis = Vec3f(i % 2 ? 1.f : 0.3f, i / 2 ? 0.5f : -0.2f, i % 3 ? 0.4f : -0.6f).normalized();
    for (const char* name : spine)
      if (int j = sk.find(name); j >= 0) p.local[size_t(j)] = Quatf(Eigen::AngleAxisf(0.25f + 0.1f * float(i), axis));
    for (const char* arm : {"LeftArm", "RightArm"})
      if (int j = sk.find(arm); j >= 0) p.local[size_t(j)] = Quatf(Eigen::AngleAxisf(0.4f, Vec3f::UnitZ()));
    poses.push_back(p);
  }
  return poses;
}

void runPoses(benchmark::State& state, const Character& ch, size_t vertices = 0, float attachBand = -1.f) {
  ClothSimSettings settings;
  settings.sweepKernel = SweepKernel(state.range(0));
  if (attachBand >= 0.f) settings.attachTopFraction = attachBand;
  const ClothSolver solver(ch, vertices ? buildSimulationMesh(ch, vertices) : buildSimulationMesh(ch), settings);
  const ConstraintSchedule schedule = buildConstraintSchedule(solver.constraints());
  state.counters["vectorised_share"] =
      settings.sweepKernel == SweepKernel::Vector ? double(schedule.vectorised()) / double(schedule.total()) : 0.0;
  const std::vector<Pose> poses = benchPoses(ch.skeleton);
  size_t i = 0, failed = 0;
  double penetration = 0, violation = 0, residual = 0;
  int retried = 0;
  for (auto _ : state) {
    const PoseSimulation r = solver.simulate(poses[i++ % poses.size()]);
    failed += !r.ok;
    if (!r.ok && std::getenv("SWISH_BENCH_VERBOSE")) std::fprintf(stderr, "pose failed: %s\n", r.failure.c_str());
    penetration = std::max(penetration, double(r.residuals.maxPenetration));
    violation = std::max(violation, double(r.residuals.maxConstraintViolation));
    residual = std::max(residual, double(r.residuals.equilibriumResidual));
    retried += r.attempts > 1;
  }
  state.counters["sim_vertices"] = double(solver.mesh().vertexCount());
  state.counters["failed"] = double(failed);
  state.counters["max_penetration_mm"] = penetration * 1e3;
  state.counters["max_stretch_pct"] = violation * 1e2;
  // The end condition (cloth_solver.hpp): the worst pose's equilibrium residual, and the poses that
  // needed a retry (each retry costs about four first attempts).
  state.counters["max_equilibrium_residual"] = residual;
  state.counters["retried"] = double(retried);
}

void BM_ClothPose_SharedTshirt(benchmark::State& state) {
  const auto file = test::sharedAsset("tshirt_lo.glb");
  if (!std::filesystem::exists(file)) {
    state.SkipWithError(("shared test character absent: " + file.string()).c_str());
    return;
  }
  static const Character ch = io::importCharacter(file);
  runPoses(state, ch);
}

void BM_ClothPose_DefaultJersey(benchmark::State& state) {
  static const Character ch = makeDefaultCharacter();
  runPoses(state, ch, 6000, 0.03f);
}

void BM_ClothPose_CapsuleTube(benchmark::State& state) {
  test::CapsuleSpec spec;
  spec.garmentAround = 100;
  spec.garmentRows = 29;  // 3,000 game vertices (with the seam column), as the default jersey
  static const Character ch = test::capsuleCharacter(spec);
  runPoses(state, ch);
}

}  // namespace

BENCHMARK(BM_ClothPose_SharedTshirt)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kSecond)
    ->Iterations(4)
    ->Repetitions(3)
    ->ReportAggregatesOnly(false);
BENCHMARK(BM_ClothPose_DefaultJersey)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kSecond)
    ->Iterations(4)
    ->Repetitions(3)
    ->ReportAggregatesOnly(false);
BENCHMARK(BM_ClothPose_CapsuleTube)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kSecond)
    ->Iterations(4)
    ->Repetitions(3)
    ->ReportAggregatesOnly(false);
BENCHMARK_MAIN();
