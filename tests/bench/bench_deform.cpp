// The deform pass on the selected Vulkan device (SWISH_DEVICE; lavapipe here): 1 and 22 instances of a
// 3000-vertex, K = 30 model, timed with GPU timestamps, its bytes moved per second reported against a
// plain vec4 copy kernel of the same byte count measured in the same iterations (vs_copy: goal >= 0.5);
// and the cost of an empty dispatch (one alone, and amortised over 100 back to back). Also the
// tangent-frames pass on the same 22 deformed instances, single-pass kernel vs the two-pass
// (per-triangle terms + per-vertex gather) that FrameRecorder uses. And the push-out step of the deform
// (each vertex kept off the body by its anchor's plane, runtime/reference_push_out.hpp): the same
// dispatch with and without it,
// alternating, its share of the deform pass reported (goal <= 10%). And quality levels (issue 21): the
// deform pass and the whole frame (FrameRecorder) of 22 characters of the committed default model
// (assets/default/default.swish) at each level of its default ladder, and at a mix of them.
//   ./bench_deform --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "support/paths.hpp"
#include "support/random_model.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/copy_vec4_pass.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/gpu/empty_dispatch_pass.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"
#include "swish/gpu/timestamp_queries.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish {
namespace {

gpu::Context* benchContext() {
  static std::unique_ptr<gpu::Context> ctx;
  static bool tried = false;
  if (!tried) {
    tried = true;
    gpu::ContextOptions o;
    o.validation = false;  // the layers would time themselves
    auto made = gpu::Context::tryCreate(o);
    if (made)
      ctx = std::make_unique<gpu::Context>(std::move(made.value()));
    else
      std::fprintf(stderr, "bench_deform: no Vulkan device: %s\n", made.error().what());
    if (ctx) std::fprintf(stderr, "bench_deform: device %s\n", ctx->deviceName().c_str());
  }
  return ctx.get();
}

// GPU time of what `record` records, in seconds, from timestamps around it. On a fast GPU a small pass takes
// microseconds while a submit and its fence wait take one or two milliseconds of CPU (an H100 here):
// timed one pass per submit, a benchmark's minimum time needs tens of thousands of submits per run. So a
// timed region may record the pass `reps` times back to back, with a compute-to-compute barrier between
// them as consecutive frames have. `repsFor` picks reps once so that a region lasts at least
// kTimedRegionSeconds of GPU time; on lavapipe one pass lasts longer than that, and reps is 1. The
// benchmarks that use it report the region as the iteration's time and the pass in `pass_us`.
constexpr double kTimedRegionSeconds = 200e-6;

template <class F>
double gpuSeconds(gpu::Context& ctx, gpu::TimestampQueries& ts, F&& record, uint32_t reps = 1) {
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    ts.reset(cmd);
    ts.mark(cmd, 0);
    for (uint32_t r = 0; r < reps; ++r) {
      if (r > 0) gpu::computeToComputeBarrier(cmd);
      record(cmd);
    }
    ts.mark(cmd, 1);
  });
  return ts.readNs()[1] * 1e-9;
}

// Reps for `record` (after its warm-up): see the comment above gpuSeconds.
template <class F>
uint32_t repsFor(gpu::Context& ctx, gpu::TimestampQueries& ts, F&& record) {
  const double once = gpuSeconds(ctx, ts, record);
  return uint32_t(std::clamp(std::ceil(kTimedRegionSeconds / std::max(once, 1e-9)), 1.0, 1024.0));
}

struct DeformSetup {
  Model model;
  std::unique_ptr<gpu::GpuModel> gpuModel;
  gpu::Buffer weights, matrices, positions, copySrc, copyDst;
  std::unique_ptr<gpu::DeformPass> pass;
  gpu::DescriptorBinding instanceInputs;
  std::unique_ptr<gpu::CopyVec4Pass> copy;
  double bytesMoved = 0;
  uint32_t copyVec4s = 0;
};

DeformSetup makeSetup(gpu::Context& ctx, uint32_t instances, bool skinning, uint32_t components = 30,
                      uint32_t anchorSets = 0) {
  DeformSetup s;
  Rng rng(42);
  test::RandomModelSpec spec;
  spec.vertices = 3000;
  spec.meshComponents = components;
  spec.bodyAnchors = anchorSets > 0;
  spec.secondAnchors = anchorSets > 1;
  spec.thirdAnchors = anchorSets > 2;
  spec.influences = 4;
  spec.joints = 24;
  spec.normalMaps = 0;
  s.model = test::makeRandomModel(rng, spec);
  s.gpuModel = std::make_unique<gpu::GpuModel>(ctx, s.model);
  const size_t n = 3000, k = components;
  std::vector<float> w(instances * k);
  for (auto& x : w) x = float(rng.normal());
  std::vector<Mat4f> m;
  for (uint32_t i = 0; i < instances; ++i) {
    const auto mats = s.model.skeleton.skinningMatrices(test::makeRandomPose(rng, s.model.skeleton));
    m.insert(m.end(), mats.begin(), mats.end());
  }
  std::vector<float> rows(gpu::DeformPass::weightsBytes(instances, uint32_t(k)) / 4);
  gpu::DeformPass::packWeights(w.data(), instances, uint32_t(k), rows.data());
  s.weights = gpu::Buffer(ctx, rows.size() * 4, gpu::MemoryKind::DeviceLocal, "weights");
  s.weights.upload(ctx, rows.data(), rows.size() * 4);
  std::vector<float> matrixRows(m.size() * 12);
  gpu::DeformPass::packSkinMatrices(m.data(), m.size(), matrixRows.data());
  s.matrices = gpu::Buffer(ctx, matrixRows.size() * 4, gpu::MemoryKind::DeviceLocal, "matrices");
  s.matrices.upload(ctx, matrixRows.data(), matrixRows.size() * 4);
  s.positions = gpu::Buffer(ctx, instances * n * 12, gpu::MemoryKind::DeviceLocal, "positions");
  // The basis as texels where the device allows (as FrameRecorder runs it).
  s.pass = std::make_unique<gpu::DeformPass>(
      ctx, uint32_t(k), 4, skinning, s.gpuModel->basis.size() / sizeof(float), skinning ? s.gpuModel->anchorSlots() : 0,
      skinning ? s.gpuModel->anchorExtraJoints() : 0, s.gpuModel->anchorZeroSkip());
  s.instanceInputs = s.pass->bindInstanceInputs(ctx, s.weights, s.matrices, &s.gpuModel->basis, &s.gpuModel->anchors);
  // Bytes the kernel must move at least once: basis, mean, skin influences, weights, matrices, output.
  s.bytesMoved = double(n * k * 3 * 4 + n * 3 * 4 + n * 4 * 8 + w.size() * 4 + m.size() * 48 + instances * n * 12);
  // The copy moves the same bytes: reads half, writes half.
  s.copyVec4s = uint32_t(s.bytesMoved / 32);
  s.copySrc = gpu::Buffer(ctx, size_t(s.copyVec4s) * 16, gpu::MemoryKind::DeviceLocal, "copy src");
  s.copyDst = gpu::Buffer(ctx, size_t(s.copyVec4s) * 16, gpu::MemoryKind::DeviceLocal, "copy dst");
  s.copy = std::make_unique<gpu::CopyVec4Pass>(ctx);
  return s;
}

void BM_Deform(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t instances = uint32_t(state.range(0));
  DeformSetup s = makeSetup(*ctx, instances, state.range(1) != 0);
  gpu::TimestampQueries ts(*ctx, 2);
  gpu::DeformPass::Args a = s.gpuModel->deformArgs(s.instanceInputs.get(), s.positions, instances);
  // Warm-up: lavapipe compiles a pipeline at its first dispatch; that is not the kernel's cost.
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, a); });
  gpuSeconds(*ctx, ts,
             [&](VkCommandBuffer cmd) { s.copy->record(cmd, s.copySrc.address(), s.copyDst.address(), s.copyVec4s); });
  const auto deform = [&](VkCommandBuffer cmd) { s.pass->record(cmd, a); };
  const auto copy = [&](VkCommandBuffer cmd) {
    s.copy->record(cmd, s.copySrc.address(), s.copyDst.address(), s.copyVec4s);
  };
  const uint32_t reps = repsFor(*ctx, ts, deform);
  double deformTotal = 0, copyTotal = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, deform, reps);
    const double c = gpuSeconds(*ctx, ts, copy, reps);
    state.SetIterationTime(t);
    deformTotal += t;
    copyTotal += c;
  }
  const double passes = double(state.iterations()) * reps;
  const double deformBw = s.bytesMoved * passes / deformTotal;
  const double copyBw = double(s.copyVec4s) * 32 * passes / copyTotal;
  state.counters["deform_GBps"] = deformBw * 1e-9;
  state.counters["copy_GBps"] = copyBw * 1e-9;
  state.counters["vs_copy"] = deformBw / copyBw;
  state.counters["pass_us"] = 1e6 * deformTotal / passes;
  state.counters["us_per_instance"] = 1e6 * deformTotal / passes / instances;
  state.counters["reps"] = reps;
}
// Args: instances, skinning (0: PCA reconstruction only, to see what skinning costs).
BENCHMARK(BM_Deform)
    ->Args({1, 1})
    ->Args({22, 1})
    ->Args({22, 0})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(0.5);

// Times `pass` with `plain` (no push-out: the kernel without its code, deform.glsl) and with the model's
// push-out added, alternating each iteration so that drift of a shared machine hits both alike. Time: the
// region with the push-out; counters `pass_us` and `plain_us` one pass each, `pushout_share` the extra
// time over the plain pass.
void timePushOut(benchmark::State& state, gpu::Context& ctx, const gpu::DeformPass& pass, const gpu::GpuModel& model,
                 const gpu::DeformPass::Args& plainArgs) {
  gpu::DeformPass::Args pushed = plainArgs;
  pushed.anchors = model.anchors.address();
  pushed.anchorSlots = model.anchorSlots();
  gpu::TimestampQueries ts(ctx, 2);
  const auto withPush = [&](VkCommandBuffer cmd) { pass.record(cmd, pushed); };
  const auto plain = [&](VkCommandBuffer cmd) { pass.record(cmd, plainArgs); };
  gpuSeconds(ctx, ts, withPush);  // warm-up (lavapipe compiles each pipeline at its first dispatch)
  gpuSeconds(ctx, ts, plain);
  const uint32_t reps = repsFor(ctx, ts, plain);
  double with = 0, without = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(ctx, ts, withPush, reps);
    without += gpuSeconds(ctx, ts, plain, reps);
    state.SetIterationTime(t);
    with += t;
  }
  const double passes = double(state.iterations()) * reps;
  state.counters["pass_us"] = 1e6 * with / passes;
  state.counters["plain_us"] = 1e6 * without / passes;
  state.counters["pushout_share"] = (with - without) / without;
  state.counters["reps"] = reps;
  state.counters["anchor_sets"] = model.anchorSlots();
}

// The deform pass with and without its push-out step: args instances, K, anchor sets (1: BodyAnchors::
// anchors, 2: and BodyAnchors::second, 3: and BodyAnchors::third; the random model leaves every 7th vertex
// without a first anchor, every 5th without a second, every 3rd without a third). Each iteration times both
// dispatches (alternating, so that drift of a shared machine hits both alike); the reported time is the
// timed region with the push-out (`pass_us` one pass), `pushout_share` its extra time over the plain deform.
void BM_DeformPushOut(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t instances = uint32_t(state.range(0)), k = uint32_t(state.range(1));
  DeformSetup s = makeSetup(*ctx, instances, true, k, uint32_t(state.range(2)));
  timePushOut(state, *ctx, *s.pass, *s.gpuModel,
              s.gpuModel->deformArgs(s.instanceInputs.get(), s.positions, instances));
}
// Args: instances, K, anchor sets. K = 128 is the default model's.
BENCHMARK(BM_DeformPushOut)
    ->Args({22, 30, 1})
    ->Args({22, 128, 1})
    ->Args({22, 128, 2})
    ->Args({22, 128, 3})
    ->Args({1, 128, 2})
    ->Args({1, 128, 3})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(0.5);

// Normals + tangents of `instances` deformed instances of the 3000-vertex model (a UV-mapped grid,
// ~5900 triangles), arg 1: 0 = single-pass tangent_frames.comp, 1 = two passes through a
// triangle-terms buffer (what FrameRecorder records).
void BM_TangentFrames(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t instances = uint32_t(state.range(0));
  const bool twoPass = state.range(1) != 0;
  DeformSetup s = makeSetup(*ctx, instances, true);
  const gpu::GpuModel& g = *s.gpuModel;
  gpu::TimestampQueries ts(*ctx, 2);
  gpu::DeformPass::Args d = g.deformArgs(s.instanceInputs.get(), s.positions, instances);
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, d); });  // the positions to frame
  const VkDeviceSize n = g.vertexCount();
  gpu::Buffer normals(*ctx, instances * n * 12, gpu::MemoryKind::DeviceLocal, "normals");
  gpu::Buffer tangents(*ctx, instances * n * 16, gpu::MemoryKind::DeviceLocal, "tangents");
  gpu::Buffer terms(*ctx, gpu::TangentFramesPass::triangleTermsBytes(g.triangleCount(), instances),
                    gpu::MemoryKind::DeviceLocal, "triangle terms");
  const gpu::TangentFramesPass pass(*ctx);
  gpu::DescriptorBinding binding;
  if (twoPass) {
    gpu::TangentFramesPass::TwoPassBuffers b;
    b.positions = &s.positions;
    b.triangleTerms = &terms;
    b.normalOffsets = &g.normalOffsets;
    b.frameTriangles = &g.frameTriangles;
    b.normalsOut = &normals;
    b.tangentsOut = &tangents;
    binding = pass.bindTwoPass(*ctx, b);
  }
  gpu::TangentFramesPass::Args a;
  a.positions = s.positions.address();
  a.uvs = g.uvs.address();
  a.triangles = g.triangles.address();
  a.normalOffsets = g.normalOffsets.address();
  a.normalTriangles = g.normalTriangles.address();
  a.tangentOffsets = g.tangentOffsets.address();
  a.tangentTriangles = g.tangentTriangles.address();
  a.normalsOut = normals.address();
  a.tangentsOut = tangents.address();
  a.vertexCount = g.vertexCount();
  a.instanceCount = instances;
  a.hasUvs = g.hasUvs();
  if (twoPass) {
    a.twoPass = binding.get();
    a.triangleCount = g.triangleCount();
  }
  const auto frames = [&](VkCommandBuffer cmd) { pass.record(cmd, a); };
  gpuSeconds(*ctx, ts, frames);  // warm-up (first-use compile)
  const uint32_t reps = repsFor(*ctx, ts, frames);
  state.counters["reps"] = reps;
  double total = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, frames, reps);
    state.SetIterationTime(t);
    total += t;
  }
  const double passes = double(state.iterations()) * reps;
  state.counters["pass_us"] = 1e6 * total / passes;
  state.counters["us_per_instance"] = 1e6 * total / passes / instances;
}
BENCHMARK(BM_TangentFrames)->Args({22, 0})->Args({22, 1})->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// One empty dispatch between two timestamps (arg 1), or 100 back to back (arg 100); Time is the timed
// region, `us_per_dispatch` the region over its dispatches.
void BM_EmptyDispatch(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t n = uint32_t(state.range(0));
  gpu::EmptyDispatchPass empty(*ctx);
  gpu::TimestampQueries ts(*ctx, 2);
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { empty.record(cmd, n); });  // warm-up (first-use compile)
  double total = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { empty.record(cmd, n); });
    state.SetIterationTime(t);
    total += t;
  }
  state.counters["dispatches"] = n;
  state.counters["us_per_dispatch"] = 1e6 * total / double(state.iterations()) / n;
}
BENCHMARK(BM_EmptyDispatch)->Arg(1)->Arg(100)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.3);

// Quality levels ---------------------------------------------------------------------------------

// The committed default model on the device, and its default ladder (runtime::defaultLadder: full,
// k64, k32-flat, k16-flat, skinned for its K = 128 with maps). SWISH_DEFAULT_MODEL overrides the path
// (a build run from another checkout).
struct DefaultModel {
  Model model;
  std::unique_ptr<gpu::GpuModel> gpu;
  runtime::QualityLadder ladder;
};

const DefaultModel* defaultModel(gpu::Context& ctx) {
  static std::unique_ptr<DefaultModel> m;
  static bool tried = false;
  if (!tried) {
    tried = true;
    const char* env = std::getenv("SWISH_DEFAULT_MODEL");
    const std::filesystem::path file =
        env ? std::filesystem::path(env) : test::sourceDir() / "assets/default/default.swish";
    if (std::filesystem::exists(file)) {
      m = std::make_unique<DefaultModel>();
      m->model = loadModel(file);
      m->gpu = std::make_unique<gpu::GpuModel>(ctx, m->model, "default");
      m->ladder = runtime::defaultLadder(m->model);
      std::fprintf(stderr, "bench_deform: %s: %u vertices, K %d, ladder", file.c_str(), m->gpu->vertexCount(),
                   m->model.meshComponents());
      for (const auto& l : m->ladder.levels) std::fprintf(stderr, " %s", l.name.c_str());
      std::fprintf(stderr, "\n");
    }
  }
  return m.get();
}

// The level of each of `instances` characters: all at ladder level `level`; for level ==
// ladder.size() a mix (a crowd seen from the side line: a few near at full, most far): per 11
// characters 2 full, 2 at level 1, 3 at level 2, 2 at level 3, 2 at the last level; for
// ladder.size() + 1 all at full but one at the last level (the frame where bands gain least).
std::vector<size_t> levelsOf(const runtime::QualityLadder& ladder, size_t level, uint32_t instances) {
  std::vector<size_t> out(instances, level);
  if (level == ladder.size()) {
    static const size_t mix[11] = {0, 0, 1, 1, 2, 2, 2, 3, 3, 4, 4};
    for (uint32_t i = 0; i < instances; ++i) out[i] = std::min(mix[i % 11], ladder.size() - 1);
  } else if (level == ladder.size() + 1) {  // all full but the last, at the cheapest level
    std::fill(out.begin(), out.end(), 0);
    out.back() = ladder.size() - 1;
  }
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// `count` mesh PCA weights drawn from a standard normal (the default model's weights are of that size).
std::vector<float> randomMeshWeights(size_t count, Rng& rng) {
  std::vector<float> w(count);
  for (auto& x : w) x = float(rng.normal());
  return w;
}

// The deform's output for `instances` instances of model g.
gpu::Buffer positionsBuffer(gpu::Context& ctx, const gpu::GpuModel& g, uint32_t instances) {
  return gpu::Buffer(ctx, VkDeviceSize(instances) * g.vertexCount() * 12, gpu::MemoryKind::DeviceLocal, "positions");
}

// The skinning matrix rows of `instances` random poses of `skeleton` (0.3 rad per joint), on the device.
gpu::Buffer randomPoseMatrices(gpu::Context& ctx, const Skeleton& skeleton, uint32_t instances, Rng& rng) {
  std::vector<Mat4f> mats;
  for (uint32_t i = 0; i < instances; ++i) {
    const auto m = skeleton.skinningMatrices(test::makeRandomPose(rng, skeleton, 0.3f));
    mats.insert(mats.end(), m.begin(), m.end());
  }
  std::vector<float> matrixRows(mats.size() * 12);
  gpu::DeformPass::packSkinMatrices(mats.data(), mats.size(), matrixRows.data());
  gpu::Buffer matrices(ctx, matrixRows.size() * 4, gpu::MemoryKind::DeviceLocal, "matrices");
  matrices.upload(ctx, matrixRows.data(), matrixRows.size() * 4);
  return matrices;
}

// The configurations timed against each other: "full_nobands" (the pipeline without bands: every
// instance reads all K, the pass as it was before levels and as FrameRecorder runs a frame without
// levels), then each ladder level for all 22 characters (the pipeline with bands), then the mix.
// Every iteration times each once, in turn, so that the drift of a shared machine (lavapipe runs on
// its CPUs) hits all alike; the counters are per-configuration medians.
struct LevelConfig {
  std::string name;
  size_t level;  // ladder index, ladder.size(): mixed
  bool bands;    // the pipeline with bands (FrameRecorder's whenever an instance is below K)
};

std::vector<LevelConfig> levelConfigs(const runtime::QualityLadder& ladder, bool withUnbanded) {
  std::vector<LevelConfig> c;
  if (withUnbanded) c.push_back({"full_nobands", 0, false});
  for (size_t l = 0; l < ladder.size(); ++l) c.push_back({ladder[l].name, l, true});
  c.push_back({"mixed", ladder.size(), true});
  c.push_back({"one_" + ladder.levels.back().name, ladder.size() + 1, true});
  return c;
}

// The deform pass alone: 22 instances of the default model per configuration (levelConfigs); reports
// the median GPU time of each in microseconds (<name>_us).
void BM_DeformLevels(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const DefaultModel* dm = defaultModel(*ctx);
  if (!dm) return state.SkipWithError("no committed default model");
  const gpu::GpuModel& g = *dm->gpu;
  const uint32_t instances = 22, k = g.kernelMeshComponents();
  Rng rng(21);
  const std::vector<float> w = randomMeshWeights(instances * k, rng);
  const gpu::Buffer matrices = randomPoseMatrices(*ctx, dm->model.skeleton, instances, rng);
  const gpu::Buffer positions = positionsBuffer(*ctx, g, instances);
  // As FrameRecorder makes it (the frames here have no push-out).
  const gpu::DeformPass pass = g.makeDeformPass(*ctx);
  struct Run {
    gpu::Buffer weights, order;
    gpu::DescriptorBinding inputs;
    gpu::DeformPass::Args args;
    std::vector<double> us;
    uint32_t reps = 1;
  };
  const std::vector<LevelConfig> configs = levelConfigs(dm->ladder, true);
  std::vector<Run> runs(configs.size());
  for (size_t c = 0; c < configs.size(); ++c) {
    std::vector<uint32_t> components;
    for (size_t l : levelsOf(dm->ladder, configs[c].level, instances))
      components.push_back(dm->ladder[l].meshComponents);
    std::vector<float> rows(gpu::DeformPass::weightsBytes(instances, k) / 4);
    gpu::DeformPass::packWeights(w.data(), instances, k, components, rows.data());
    const gpu::DeformPass::Levels levels = gpu::DeformPass::packLevels(components, k);
    Run& r = runs[c];
    r.weights = gpu::Buffer(*ctx, rows.size() * 4, gpu::MemoryKind::DeviceLocal, "weights");
    r.weights.upload(*ctx, rows.data(), rows.size() * 4);
    r.order = gpu::Buffer(*ctx, levels.order.size() * 4, gpu::MemoryKind::DeviceLocal, "instance order");
    r.order.upload(*ctx, levels.order.data(), levels.order.size() * 4);
    r.inputs = pass.bindInstanceInputs(*ctx, r.weights, matrices, &g.basis, &g.anchors);
    gpu::DeformPass::Args& a = r.args;
    a = g.deformArgs(r.inputs.get(), positions, instances);
    if (configs[c].bands) {
      a.instanceOrder = r.order.address();
      a.bandEnd = levels.bandEnd;
      a.maxGroups = levels.maxGroups;
    }
  }
  gpu::TimestampQueries ts(*ctx, 2);
  for (Run& r : runs) {
    const auto deform = [&](VkCommandBuffer cmd) { pass.record(cmd, r.args); };
    gpuSeconds(*ctx, ts, deform);  // warm-up (first-use compile)
    r.reps = repsFor(*ctx, ts, deform);
  }
  for (auto _ : state) {
    double sum = 0;
    for (Run& r : runs) {
      const double t = gpuSeconds(
          *ctx, ts, [&](VkCommandBuffer cmd) { pass.record(cmd, r.args); }, r.reps);
      r.us.push_back(t * 1e6 / r.reps);
      sum += t;
    }
    state.SetIterationTime(sum);
  }
  for (size_t c = 0; c < configs.size(); ++c) state.counters[configs[c].name + "_us"] = median(runs[c].us);
  state.SetLabel("22 instances of the default model, medians per level; Time: a timed region of each in turn");
}
BENCHMARK(BM_DeformLevels)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(2.0);

// The committed default model's own push-out (its anchor sets, as the scene runs them), arg: instances. The
// deform pass at full K with and without it, alternating as in BM_DeformPushOut; `pushout_share` its extra
// time over the plain pass.
void BM_DeformPushOutDefaultModel(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const DefaultModel* dm = defaultModel(*ctx);
  if (!dm) return state.SkipWithError("no committed default model");
  const gpu::GpuModel& g = *dm->gpu;
  if (!g.hasBodyAnchors()) return state.SkipWithError("the default model has no body anchors");
  const uint32_t instances = uint32_t(state.range(0)), k = g.kernelMeshComponents();
  Rng rng(23);
  const std::vector<float> w = randomMeshWeights(instances * k, rng);
  std::vector<float> rows(gpu::DeformPass::weightsBytes(instances, k) / 4);
  gpu::DeformPass::packWeights(w.data(), instances, k, rows.data());
  gpu::Buffer weights(*ctx, rows.size() * 4, gpu::MemoryKind::DeviceLocal, "weights");
  weights.upload(*ctx, rows.data(), rows.size() * 4);
  const gpu::Buffer matrices = randomPoseMatrices(*ctx, dm->model.skeleton, instances, rng);
  const gpu::Buffer positions = positionsBuffer(*ctx, g, instances);
  const gpu::DeformPass pass = g.makeDeformPass(*ctx);
  const gpu::DescriptorBinding inputs = pass.bindInstanceInputs(*ctx, weights, matrices, &g.basis, &g.anchors);
  timePushOut(state, *ctx, pass, g, g.deformArgs(inputs.get(), positions, instances));
}
BENCHMARK(BM_DeformPushOutDefaultModel)->Arg(22)->Arg(1)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// Whole frames (FrameRecorder: deform, normals + tangents, VQ decode, blend; two frames in flight) of
// 22 characters of the default model, one recorder per configuration (levelConfigs), a frame of each in
// turn per iteration, from GPU timestamps. Every character with maps selects a random database map
// every frame (the decode's worst case: few maps are still in a slot); characters at a level without
// maps select kNoMap. Counters: median frame time per configuration (<name>_us); the median per stage
// goes to stderr.
void BM_FrameLevels(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const DefaultModel* dm = defaultModel(*ctx);
  if (!dm) return state.SkipWithError("no committed default model");
  const Model& model = dm->model;
  const uint32_t instances = 22, k = uint32_t(model.meshComponents()), maps = model.normalMaps.mapCount();
  struct Run {
    std::unique_ptr<gpu::FrameRecorder> recorder;
    std::vector<size_t> levels;
    runtime::FrameKernelInputs in;
    std::vector<double> deform, frames, decode, blend, total;  // us
  };
  const std::vector<LevelConfig> configs = levelConfigs(dm->ladder, false);
  std::vector<Run> runs(configs.size());
  Rng rng(22);
  for (size_t c = 0; c < configs.size(); ++c) {
    Run& r = runs[c];
    r.recorder = std::make_unique<gpu::FrameRecorder>(*ctx, *dm->gpu, instances);
    r.levels = levelsOf(dm->ladder, configs[c].level, instances);
    runtime::FrameKernelInputs& in = r.in;
    in.instanceCount = instances;
    in.meshWeights.resize(size_t(instances) * k);
    for (auto& x : in.meshWeights) x = float(rng.normal());
    for (uint32_t i = 0; i < instances; ++i) {
      const auto m = model.skeleton.skinningMatrices(test::makeRandomPose(rng, model.skeleton, 0.3f));
      in.skinMatrices.insert(in.skinMatrices.end(), m.begin(), m.end());
      in.meshComponents.push_back(dm->ladder[r.levels[i]].meshComponents);
    }
    in.blendAlpha.assign(instances, 0.3f);
    in.selectedMaps.assign(instances, runtime::kNoMap);
  }
  uint64_t frame = 0;
  auto runFrame = [&](Run& r, bool keep) {
    for (uint32_t i = 0; i < instances && maps > 0; ++i)
      r.in.selectedMaps[i] = dm->ladder[r.levels[i]].normalMaps ? uint32_t(rng.below(maps)) : runtime::kNoMap;
    const uint64_t f = frame;
    ctx->submitAndWait([&](VkCommandBuffer cmd) { r.recorder->record(cmd, f, r.in); });
    const gpu::StageTimes t = r.recorder->stageTimes(r.recorder->slotOf(f));
    const auto us = [](double ms) { return std::isnan(ms) ? 0.0 : ms * 1e3; };
    if (keep) {
      r.deform.push_back(us(t.deformMs));
      r.frames.push_back(us(t.tangentFramesMs));
      r.decode.push_back(us(t.vqDecodeMs));
      r.blend.push_back(us(t.normalBlendMs));
      r.total.push_back(us(t.totalMs));
    }
    return t.totalMs * 1e-3;
  };
  for (int i = 0; i < 3; ++i, ++frame)  // warm-up: first-use compiles, both slots
    for (Run& r : runs) runFrame(r, false);
  for (auto _ : state) {
    double sum = 0;
    for (Run& r : runs) sum += runFrame(r, true);
    ++frame;
    state.SetIterationTime(sum);
  }
  std::fprintf(stderr, "bench_deform: BM_FrameLevels medians (us), %zu frames each:\n  %-10s %8s %8s %8s %8s %8s\n",
               runs[0].total.size(), "level", "deform", "frames", "decode", "blend", "total");
  for (size_t c = 0; c < configs.size(); ++c) {
    const Run& r = runs[c];
    std::fprintf(stderr, "  %-10s %8.0f %8.0f %8.0f %8.0f %8.0f\n", configs[c].name.c_str(), median(r.deform),
                 median(r.frames), median(r.decode), median(r.blend), median(r.total));
    state.counters[configs[c].name + "_us"] = median(r.total);
  }
  state.SetLabel("22 characters of the default model, medians per level; Time: all of them in turn");
}
BENCHMARK(BM_FrameLevels)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(5.0);

}  // namespace
}  // namespace swish

BENCHMARK_MAIN();
