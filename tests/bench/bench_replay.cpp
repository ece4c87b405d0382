// Per-frame cost of `swish replay` on the default scene (assets/scenes/football.json: 22 characters of
// the default model, CMU mocap) and on the same scene cut to 1 character, in one run, on the selected
// Vulkan device (lavapipe here). Goal: 22 characters cost <= 6x one character, thanks to batching.
//
// Each iteration replays kFrames frames (no GPU-vs-CPU checks: outputs.gpuCheckEvery is set beyond
// the frame count). Counters per frame: cpu_ms (poses, FK, Theta, MLP, lookup, filter, recording),
// gpu_ms (GPU timestamps of all passes), wall_ms (CPU + submit-to-fence). BM_ReplayRatio reports
// ratio_cpu, ratio_gpu and ratio_wall of 22 characters over 1, measured in the same process, and the
// ratio of each GPU stage (deform, tangent frames, VQ decode, normal-map blend). All of these are
// medians over the frames; gpu_min_ms / ratio_gpu_min (the fastest frame of each) are beside them
// because on a machine shared with other jobs lavapipe's threads are preempted, which moves the
// medians of the longer 22-character frames far more than those of 1 character. The fastest frame of
// each GPU stage (deform_min_ms, tangents_min_ms, blend_min_ms) is there for the same reason: A/B
// comparisons of a stage on a busy machine.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "support/paths.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_engine.hpp"
#include "swish/runtime/scene_file.hpp"

namespace {

using namespace swish;
constexpr uint32_t kFrames = 8;

struct PerFrame {
  double cpu = 0, gpu = 0, wall = 0;
  double deform = 0, tangents = 0, decode = 0, blend = 0;  // GPU stages
  double gpuMin = 0;
  double deformMin = 0, tangentsMin = 0, blendMin = 0;  // the fastest frame of each GPU stage
};
std::map<int, PerFrame> g_results;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}
double minimum(const std::vector<double>& v) { return v.empty() ? NAN : *std::min_element(v.begin(), v.end()); }

void BM_ReplayDefaultScene(benchmark::State& state) {
  const int characters = int(state.range(0));
  runtime::Scene scene = runtime::loadScene(test::sourceDir() / "assets/scenes/football.json");
  scene.characters.resize(size_t(characters));
  scene.frameCount = kFrames;
  scene.outputs.gpuCheckEvery = kFrames + 1;  // frame 0 is still checked once: excluded below
  replay::ModelLibrary models(scene);
  replay::ReplayEngine engine(scene, models);
  std::vector<double> cpu, gpu, wall, deform, tangents, decode, blend;
  for (auto _ : state) {
    const replay::ReplayResult r = engine.run();
    for (size_t f = 1; f < r.frames.size(); ++f) {
      const auto& t = r.frames[f].times;
      cpu.push_back(t.cpuTotal());
      gpu.push_back(t.gpuTotal);
      wall.push_back(t.cpuTotal() + t.gpuWait);
      deform.push_back(t.gpuDeform);
      tangents.push_back(t.gpuTangents);
      decode.push_back(t.gpuDecode);
      blend.push_back(t.gpuBlend);
    }
  }
  PerFrame p{median(cpu),   median(gpu),     median(wall),      median(deform), median(tangents), median(decode),
             median(blend), minimum(gpu),    minimum(deform),   minimum(tangents), minimum(blend)};
  g_results[characters] = p;
  state.counters["cpu_ms"] = p.cpu;
  state.counters["gpu_ms"] = p.gpu;
  state.counters["wall_ms"] = p.wall;
  // Where the GPU time goes (medians of each stage on its own, so they need not add up to gpu_ms).
  state.counters["deform_ms"] = p.deform;
  state.counters["tangents_ms"] = p.tangents;
  state.counters["decode_ms"] = p.decode;
  state.counters["blend_ms"] = p.blend;
  state.counters["gpu_min_ms"] = p.gpuMin;
  state.counters["deform_min_ms"] = p.deformMin;
  state.counters["tangents_min_ms"] = p.tangentsMin;
  state.counters["blend_min_ms"] = p.blendMin;
  state.counters["cpu_us_per_character"] = p.cpu * 1000.0 / characters;
  state.counters["gpu_us_per_character"] = p.gpu * 1000.0 / characters;
  state.SetLabel(models.entries().front()->procedural ? "procedural stand-in model" : models.entries().front()->label);
}
BENCHMARK(BM_ReplayDefaultScene)->Arg(1)->Arg(22)->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_ReplayRatio(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(g_results.size());
  if (!g_results.count(1) || !g_results.count(22)) {
    state.SkipWithError("run BM_ReplayDefaultScene/1 and /22 first (same process)");
    return;
  }
  const PerFrame a = g_results[1], b = g_results[22];
  state.counters["ratio_cpu"] = b.cpu / a.cpu;
  state.counters["ratio_gpu"] = b.gpu / a.gpu;
  state.counters["ratio_wall"] = b.wall / a.wall;
  state.counters["ratio_deform"] = b.deform / a.deform;
  state.counters["ratio_tangents"] = b.tangents / a.tangents;
  state.counters["ratio_decode"] = b.decode / a.decode;
  state.counters["ratio_blend"] = b.blend / a.blend;
  state.counters["ratio_gpu_min"] = b.gpuMin / a.gpuMin;
  state.SetLabel(b.wall / a.wall <= 6.0 ? "goal met: 22 characters <= 6x one" : "goal missed: 22 characters > 6x one");
}
BENCHMARK(BM_ReplayRatio)->Iterations(1);

}  // namespace
BENCHMARK_MAIN();
