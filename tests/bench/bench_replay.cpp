// Per-frame cost of `swish replay` on the default scene (assets/scenes/football.json: 22 characters of
// the default model, CMU mocap) and on the same scene cut to 1 character, in one run, on the selected
// Vulkan device (lavapipe here). Goal: 22 characters cost <= 6x one character, thanks to batching.
//
// BM_ReplayDefaultScene/N replays kFrames frames per iteration (no GPU-vs-CPU checks:
// outputs.gpuCheckEvery is set beyond the frame count). Counters per frame: cpu_ms (poses, FK, Theta,
// MLP, lookup, filter, recording), gpu_ms (GPU timestamps of all passes), wall_ms (CPU + submit-to-
// fence), the GPU stages, and the fastest frame of each (*_min_ms) for A/B runs on a busy machine.
//
// BM_ReplayRatio measures the ratio itself: it builds both engines and ALTERNATES them, kRounds rounds
// of kFrames frames each, so that a change of load on a shared machine falls on both sides alike (run
// one after the other, 8 frames each, the ratio of medians ranged from 5.2 to 7.4 over four runs on
// this 2-core machine, mostly from the 1-character frame, whose lavapipe dispatches take 0.9 to 1.8 ms
// depending on how quickly lavapipe's threads are woken). It reports ratio_cpu, ratio_gpu and ratio_wall
// of 22 characters over 1 (medians over all frames), each GPU stage's ratio, and ratio_gpu_min /
// ratio_wall_min (fastest frame over fastest frame: the cost without preemption). The label says
// whether the median wall ratio meets the goal.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "support/paths.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_engine.hpp"
#include "swish/runtime/scene_file.hpp"

namespace {

using namespace swish;
constexpr uint32_t kFrames = 24;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}
double minimum(const std::vector<double>& v) { return v.empty() ? NAN : *std::min_element(v.begin(), v.end()); }

struct FrameSamples {
  std::vector<double> cpu, gpu, wall, deform, tangents, decode, blend;
};

runtime::Scene defaultScene(int characters) {
  runtime::Scene scene = runtime::loadScene(test::sourceDir() / "assets/scenes/football.json");
  scene.characters.resize(size_t(characters));
  scene.frameCount = kFrames;
  scene.outputs.gpuCheckEvery = kFrames + 1;  // frame 0 is still checked once: excluded below
  return scene;
}

// One replay of kFrames frames; frame 0 (checked against the CPU, first use of every pipeline) is left out.
void replayOnce(replay::ReplayEngine& engine, FrameSamples& s) {
  const replay::ReplayResult r = engine.run();
  for (size_t f = 1; f < r.frames.size(); ++f) {
    const auto& t = r.frames[f].times;
    s.cpu.push_back(t.cpuTotal());
    s.gpu.push_back(t.gpuTotal);
    s.wall.push_back(t.cpuTotal() + t.gpuWait);
    s.deform.push_back(t.gpuDeform);
    s.tangents.push_back(t.gpuTangents);
    s.decode.push_back(t.gpuDecode);
    s.blend.push_back(t.gpuBlend);
  }
}

void BM_ReplayDefaultScene(benchmark::State& state) {
  const int characters = int(state.range(0));
  const runtime::Scene scene = defaultScene(characters);
  replay::ModelLibrary models(scene);
  replay::ReplayEngine engine(scene, models);
  FrameSamples s;
  for (auto _ : state) replayOnce(engine, s);
  state.counters["cpu_ms"] = median(s.cpu);
  state.counters["gpu_ms"] = median(s.gpu);
  state.counters["wall_ms"] = median(s.wall);
  // Where the GPU time goes (medians of each stage on its own, so they need not add up to gpu_ms).
  state.counters["deform_ms"] = median(s.deform);
  state.counters["tangents_ms"] = median(s.tangents);
  state.counters["decode_ms"] = median(s.decode);
  state.counters["blend_ms"] = median(s.blend);
  state.counters["gpu_min_ms"] = minimum(s.gpu);
  state.counters["deform_min_ms"] = minimum(s.deform);
  state.counters["tangents_min_ms"] = minimum(s.tangents);
  state.counters["blend_min_ms"] = minimum(s.blend);
  state.counters["cpu_us_per_character"] = median(s.cpu) * 1000.0 / characters;
  state.counters["gpu_us_per_character"] = median(s.gpu) * 1000.0 / characters;
  state.SetLabel(models.entries().front()->procedural ? "procedural stand-in model" : models.entries().front()->label);
}
BENCHMARK(BM_ReplayDefaultScene)->Arg(1)->Arg(22)->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_ReplayRatio(benchmark::State& state) {
  constexpr int kRounds = 6;
  const runtime::Scene scene1 = defaultScene(1), scene22 = defaultScene(22);
  replay::ModelLibrary models1(scene1), models22(scene22);
  replay::ReplayEngine one(scene1, models1), many(scene22, models22);
  FrameSamples a, b;
  for (auto _ : state)
    for (int round = 0; round < kRounds; ++round) {
      replayOnce(one, a);
      replayOnce(many, b);
    }
  auto ratio = [](const std::vector<double>& x22, const std::vector<double>& x1) { return median(x22) / median(x1); };
  state.counters["ratio_cpu"] = ratio(b.cpu, a.cpu);
  state.counters["ratio_gpu"] = ratio(b.gpu, a.gpu);
  state.counters["ratio_wall"] = ratio(b.wall, a.wall);
  state.counters["ratio_deform"] = ratio(b.deform, a.deform);
  state.counters["ratio_tangents"] = ratio(b.tangents, a.tangents);
  state.counters["ratio_decode"] = ratio(b.decode, a.decode);
  state.counters["ratio_blend"] = ratio(b.blend, a.blend);
  state.counters["ratio_gpu_min"] = minimum(b.gpu) / minimum(a.gpu);
  state.counters["ratio_wall_min"] = minimum(b.wall) / minimum(a.wall);
  state.counters["wall_ms_1"] = median(a.wall);
  state.counters["wall_ms_22"] = median(b.wall);
  const double r = ratio(b.wall, a.wall);
  state.SetLabel(r <= 6.0 ? "goal met: 22 characters <= 6x one" : "goal missed: 22 characters > 6x one");
}
BENCHMARK(BM_ReplayRatio)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
