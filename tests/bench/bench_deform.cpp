// The deform pass on the selected Vulkan device (SWISH_DEVICE; lavapipe here): 1 and 22 instances of a
// 3000-vertex, K = 30 model, timed with GPU timestamps, its bytes moved per second reported against a
// plain vec4 copy kernel of the same byte count measured in the same iterations (vs_copy: goal >= 0.5);
// and the cost of an empty dispatch (one alone, and amortised over 100 back to back). Also the
// tangent-frames pass on the same 22 deformed instances, single-pass kernel vs the two-pass
// (per-triangle terms + per-vertex gather) that FrameRecorder uses. And the push-out step of the deform
// (the body proxy's capsules, runtime/reference_push_out.hpp): the same dispatch with and without it,
// alternating, its share of the deform pass reported (goal <= 10%).
//   ./bench_deform --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstdio>
#include <memory>

#include "support/random_model.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/copy_vec4_pass.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/gpu/empty_dispatch_pass.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"
#include "swish/gpu/timestamp_queries.hpp"
#include "swish/runtime/reference_push_out.hpp"

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

// GPU time of what `record` records, in seconds, from timestamps around it.
template <class F>
double gpuSeconds(gpu::Context& ctx, gpu::TimestampQueries& ts, F&& record) {
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    ts.reset(cmd);
    ts.mark(cmd, 0);
    record(cmd);
    ts.mark(cmd, 1);
  });
  return ts.readNs()[1] * 1e-9;
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
                      uint32_t capsules = 0) {
  DeformSetup s;
  Rng rng(42);
  test::RandomModelSpec spec;
  spec.vertices = 3000;
  spec.meshComponents = components;
  spec.bodyCapsules = capsules;
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
  s.pass = std::make_unique<gpu::DeformPass>(ctx, uint32_t(k), 4, skinning, s.gpuModel->basis.size() / sizeof(float));
  s.instanceInputs = s.pass->bindInstanceInputs(ctx, s.weights, s.matrices, &s.gpuModel->basis);
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
  gpu::DeformPass::Args a;
  a.mean = s.gpuModel->mean.address();
  a.basis = s.gpuModel->basis.address();
  a.instanceInputs = s.instanceInputs.get();
  a.skinJoints = s.gpuModel->skinJoints.address();
  a.skinWeights = s.gpuModel->skinWeights.address();
  a.positionsOut = s.positions.address();
  a.vertexCount = 3000;
  a.instanceCount = instances;
  a.jointCount = uint32_t(s.model.skeleton.size());
  // Warm-up: lavapipe compiles a pipeline at its first dispatch; that is not the kernel's cost.
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, a); });
  gpuSeconds(*ctx, ts,
             [&](VkCommandBuffer cmd) { s.copy->record(cmd, s.copySrc.address(), s.copyDst.address(), s.copyVec4s); });
  double deformTotal = 0, copyTotal = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, a); });
    const double c = gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) {
      s.copy->record(cmd, s.copySrc.address(), s.copyDst.address(), s.copyVec4s);
    });
    state.SetIterationTime(t);
    deformTotal += t;
    copyTotal += c;
  }
  const double deformBw = s.bytesMoved * double(state.iterations()) / deformTotal;
  const double copyBw = double(s.copyVec4s) * 32 * double(state.iterations()) / copyTotal;
  state.counters["deform_GBps"] = deformBw * 1e-9;
  state.counters["copy_GBps"] = copyBw * 1e-9;
  state.counters["vs_copy"] = deformBw / copyBw;
  state.counters["us_per_instance"] = 1e6 * deformTotal / double(state.iterations()) / instances;
}
// Args: instances, skinning (0: PCA reconstruction only, to see what skinning costs).
BENCHMARK(BM_Deform)
    ->Args({1, 1})
    ->Args({22, 1})
    ->Args({22, 0})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(0.5);

// The deform pass with and without its push-out step: args instances, K, capsules. Each iteration times
// both dispatches (alternating, so that drift of a shared machine hits both alike); the reported time
// is the pass with the push-out, `pushout_share` its extra time over the plain deform.
void BM_DeformPushOut(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t instances = uint32_t(state.range(0)), k = uint32_t(state.range(1)),
                 capsules = uint32_t(state.range(2));
  DeformSetup s = makeSetup(*ctx, instances, true, k, capsules);
  std::vector<float> posed;
  Rng rng(7);
  for (uint32_t i = 0; i < instances; ++i)
    runtime::poseBodyProxy(s.model.bodyProxy,
                           s.model.skeleton.skinningMatrices(test::makeRandomPose(rng, s.model.skeleton, 0.15f)),
                           posed);
  gpu::Buffer caps(*ctx, posed.size() * 4, gpu::MemoryKind::DeviceLocal, "posed capsules");
  caps.upload(*ctx, posed.data(), posed.size() * 4);
  gpu::TimestampQueries ts(*ctx, 2);
  gpu::DeformPass::Args a;
  a.mean = s.gpuModel->mean.address();
  a.basis = s.gpuModel->basis.address();
  a.instanceInputs = s.instanceInputs.get();
  a.skinJoints = s.gpuModel->skinJoints.address();
  a.skinWeights = s.gpuModel->skinWeights.address();
  a.positionsOut = s.positions.address();
  a.vertexCount = 3000;
  a.instanceCount = instances;
  a.jointCount = uint32_t(s.model.skeleton.size());
  gpu::DeformPass::Args pushed = a;
  pushed.capsules = caps.address();
  pushed.capsuleCount = capsules;
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, pushed); });  // warm-up
  double with = 0, without = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, pushed); });
    without += gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { s.pass->record(cmd, a); });
    state.SetIterationTime(t);
    with += t;
  }
  state.counters["plain_us"] = 1e6 * without / double(state.iterations());
  state.counters["pushout_share"] = (with - without) / without;
  state.counters["capsules"] = capsules;
}
// Args: instances, K, capsules. K = 128 is the default model's; the default model's proxy is ~20 capsules.
BENCHMARK(BM_DeformPushOut)
    ->Args({22, 30, 24})
    ->Args({22, 128, 24})
    ->Args({1, 128, 24})
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
  gpu::DeformPass::Args d;
  d.mean = g.mean.address();
  d.basis = g.basis.address();
  d.instanceInputs = s.instanceInputs.get();
  d.skinJoints = g.skinJoints.address();
  d.skinWeights = g.skinWeights.address();
  d.positionsOut = s.positions.address();
  d.vertexCount = g.vertexCount();
  d.instanceCount = instances;
  d.jointCount = g.jointCount();
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
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { pass.record(cmd, a); });  // warm-up (first-use compile)
  double total = 0;
  for (auto _ : state) {
    const double t = gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { pass.record(cmd, a); });
    state.SetIterationTime(t);
    total += t;
  }
  state.counters["us_per_instance"] = 1e6 * total / double(state.iterations()) / instances;
}
BENCHMARK(BM_TangentFrames)->Args({22, 0})->Args({22, 1})->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// One empty dispatch between two timestamps (arg 1), or 100 back to back, reported per dispatch (arg 100).
void BM_EmptyDispatch(benchmark::State& state) {
  gpu::Context* ctx = benchContext();
  if (!ctx) return state.SkipWithError("no Vulkan device");
  if (!ctx->supportsTimestamps()) return state.SkipWithError("device has no timestamps");
  const uint32_t n = uint32_t(state.range(0));
  gpu::EmptyDispatchPass empty(*ctx);
  gpu::TimestampQueries ts(*ctx, 2);
  gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { empty.record(cmd, n); });  // warm-up (first-use compile)
  for (auto _ : state)
    state.SetIterationTime(gpuSeconds(*ctx, ts, [&](VkCommandBuffer cmd) { empty.record(cmd, n); }) / n);
  state.counters["dispatches"] = n;
}
BENCHMARK(BM_EmptyDispatch)->Arg(1)->Arg(100)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.3);

}  // namespace
}  // namespace swish

BENCHMARK_MAIN();
