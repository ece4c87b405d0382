// Pose thinning at the paper's volume: ten minutes of 22 characters at 60 fps (792,000 samples) from
// the CMU clips of Debian's assimp-testmodels, thinned to ~700 poses. The characters replay the two
// clips with their own offsets, speeds and mirroring (pose_sampling), plus a little noise so that
// samples are logically unique as gameplay recordings are. Goal: < 10 s for thinPosesToCount on the
// 2-core build machine. Run with --benchmark_repetitions=5 and read the median.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <iostream>

#include "support/paths.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/poses/pose_thinning.hpp"
#include "swish/core/rng.hpp"
#include "swish/io/animation_import.hpp"

using namespace swish;

namespace {

const bake::PoseSamples& paperVolume() {
  static const bake::PoseSamples samples = [] {
    const Character character = bake::makeDefaultCharacter();
    std::vector<AnimationClip> clips;
    for (const char* name : {"01_01.bvh", "01_03.bvh"}) {
      const auto path = test::debianMocap(name);
      if (!std::filesystem::exists(path)) continue;
      clips.push_back(io::importAnimation(path, character.skeleton));
    }
    if (clips.empty()) return bake::PoseSamples{};
    bake::PoseSamplingOptions o;
    o.characters = 22;
    o.secondsPerCharacter = 600.0;
    o.sampleRate = 60.0;
    bake::PoseSamples s = bake::samplePoses(character.skeleton, clips, o);
    Rng noise(7);
    for (float& v : s.values) v += float(0.01 * noise.normal());
    return s;
  }();
  return samples;
}

void BM_ThinToCount700(benchmark::State& state) {
  const auto& s = paperVolume();
  if (s.size() == 0) {
    state.SkipWithError("CMU clips absent (install assimp-testmodels)");
    return;
  }
  bake::ThinningResult r;
  for (auto _ : state) {
    r = bake::thinPosesToCount(s, 700);
    benchmark::DoNotOptimize(r.kept.data());
  }
  state.counters["samples"] = double(s.size());
  state.counters["kept"] = double(r.kept.size());
  state.counters["tolerance"] = r.tolerance;
  state.counters["passes"] = r.passes;
}
BENCHMARK(BM_ThinToCount700)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ThinOnePassAtTolerance(benchmark::State& state) {
  const auto& s = paperVolume();
  if (s.size() == 0) {
    state.SkipWithError("CMU clips absent (install assimp-testmodels)");
    return;
  }
  static const float tol = bake::thinPosesToCount(s, 700).tolerance;
  bake::ThinningResult r;
  for (auto _ : state) {
    r = bake::thinPoses(s, tol);
    benchmark::DoNotOptimize(r.kept.data());
  }
  state.counters["kept"] = double(r.kept.size());
  state.counters["checksPerSample"] = double(r.distanceChecks) / double(s.size());
}
BENCHMARK(BM_ThinOnePassAtTolerance)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
