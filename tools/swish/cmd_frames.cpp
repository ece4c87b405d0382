// swish frames: an interim main job until `swish replay` exists. Runs a frame loop of a seeded,
// generated model (a grid "garment" skinned to a small skeleton, random PCA basis and normal-map
// database; not cloth, just the run-time shapes) for N characters on the selected Vulkan device,
// with frames in flight, and prints the per-stage GPU timestamps and the largest error of the GPU
// outputs against the CPU reference of the same frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "swish/command.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/core/rng.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/vk_check.hpp"
#include "swish/runtime/reference_frame.hpp"

namespace {

using namespace swish;

struct FramesOptions {
  uint32_t characters = 22, frames = 30, vertices = 3000, components = 30, mapSize = 64, maps = 16;
  uint32_t framesInFlight = 2;
  uint64_t seed = 1;
  std::string device;
  bool validation = false;
};

// A generated model with the run-time shapes of a real one (see the file comment).
Model generatedModel(Rng& rng, const FramesOptions& o) {
  Model m;
  const uint32_t joints = 12;
  for (uint32_t i = 0; i < joints; ++i) {
    Joint j;
    j.name = "joint" + std::to_string(i);
    j.parent = i == 0 ? -1 : int(i - 1) / 2;
    j.rest.translation = i == 0 ? Vec3f(0, 1, 0) : Vec3f(rng.uniformf(-.1f, .1f), .12f, rng.uniformf(-.03f, .03f));
    m.skeleton.joints.push_back(j);
  }
  m.skeleton.computeInverseBindFromRest();
  for (uint32_t i = 0; i < 4; ++i) m.inputJoints.push_back(i);
  const uint32_t n = std::max(1u, o.vertices), cols = std::max(1u, uint32_t(std::ceil(std::sqrt(double(n)))));
  Mesh& g = m.gameMesh;
  g.positions.resize(n, 3);
  g.uvs.resize(n, 2);
  for (uint32_t v = 0; v < n; ++v) {
    const float a = 6.2831853f * float(v % cols) / float(cols), y = float(v / cols) / float(cols);
    g.positions.row(v) << 0.15f * std::cos(a), 1.0f + 0.6f * y, 0.12f * std::sin(a);  // a tube: a torso's jersey
    g.uvs.row(v) << float(v % cols) / float(cols), y;
  }
  std::vector<uint32_t> tris;
  for (uint32_t v = 0; v + cols + 1 < n; ++v)
    if (v % cols + 1 < cols) tris.insert(tris.end(), {v, v + 1, v + cols, v + 1, v + cols + 1, v + cols});
  if (tris.empty()) tris = {0, 0, 0};
  g.triangles = Eigen::Map<const Triangles>(tris.data(), Eigen::Index(tris.size() / 3), 3);
  g.skin.influences = 4;
  for (uint32_t v = 0; v < n; ++v) {
    float w[4], sum = 0;
    for (float& x : w) sum += (x = float(rng.uniform(0.05, 1)));
    for (int k = 0; k < 4; ++k) {
      g.skin.joints.push_back(uint16_t(rng.below(joints)));
      g.skin.weights.push_back(w[k] / sum);
    }
  }
  computeVertexFrames(g.positions, g.uvs, g.triangles, buildFrameTopology(g.triangles, g.positions), g.normals,
                      g.tangents);
  m.meshPca.mean = Eigen::Map<const VecXf>(g.positions.data(), 3 * n);
  m.meshPca.basis = MatXf(3 * n, o.components);
  for (Eigen::Index i = 0; i < m.meshPca.basis.size(); ++i) m.meshPca.basis.data()[i] = float(rng.normal(0, 0.002));
  auto& db = m.normalMaps;
  if (o.maps > 0) {
    db.width = db.height = std::max(4u, o.mapSize / 4 * 4);
    db.keys = MatXf(o.maps, 4);
    for (Eigen::Index i = 0; i < db.keys.size(); ++i) db.keys.data()[i] = float(rng.normal());
    db.codebookSize = 256;
    db.codebook.resize(256 * 32);
    for (auto& c : db.codebook) c = int8_t(int(rng.below(181)) - 90);
    db.indices.resize(size_t(o.maps) * db.blocksPerMap());
    for (auto& i : db.indices) i = uint16_t(rng.below(256));
  }
  return m;
}

double maxAbsDiff(const float* a, const float* b, size_t n) {
  double e = 0;
  for (size_t i = 0; i < n; ++i) e = std::max(e, double(std::abs(a[i] - b[i])));
  return e;
}

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

int run(const FramesOptions& o) {
  gpu::ContextOptions co;
  co.device = o.device;
  if (o.validation) co.validation = true;
  gpu::Context ctx = gpu::Context::create(co);
  std::printf("device: %s (%s)%s\n", ctx.deviceName().c_str(), gpu::deviceTypeName(ctx.properties().deviceType),
              ctx.validationEnabled() ? ", validation on" : "");
  Rng rng(o.seed);
  const Model model = generatedModel(rng, o);
  std::printf(
      "model: %zu vertices, K = %d, %u normal maps of %ux%u; %u characters, %u frames, %u in flight, seed %llu\n",
      model.gameMesh.vertexCount(), model.meshComponents(), model.normalMaps.mapCount(), model.normalMaps.width,
      model.normalMaps.height, o.characters, o.frames, o.framesInFlight, (unsigned long long)o.seed);
  gpu::GpuModel gm(ctx, model, "generated model");
  gpu::FrameRecorderOptions fo;
  fo.framesInFlight = o.framesInFlight;
  gpu::FrameRecorder rec(ctx, gm, o.characters, fo);

  // One command buffer and fence per frame in flight; this loop owns submission.
  const VkDevice dev = ctx.device();
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx.queueFamily();
  VkCommandPool pool;
  SWISH_VK(vkCreateCommandPool(dev, &pci, nullptr, &pool));
  gpu::VkUnique<VkCommandPool> poolOwner(pool, [dev](VkCommandPool p) { vkDestroyCommandPool(dev, p, nullptr); });
  std::vector<VkCommandBuffer> cmds(o.framesInFlight);
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool;
  ai.commandBufferCount = o.framesInFlight;
  SWISH_VK(vkAllocateCommandBuffers(dev, &ai, cmds.data()));
  std::vector<gpu::VkUnique<VkFence>> fences;
  for (uint32_t s = 0; s < o.framesInFlight; ++s) {
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VkFence f;
    SWISH_VK(vkCreateFence(dev, &fci, nullptr, &f));
    fences.emplace_back(f, [dev](VkFence h) { vkDestroyFence(dev, h, nullptr); });
  }

  std::vector<double> deform, frames, decode, blend, total, cpuRecord;
  std::vector<bool> slotUsed(o.framesInFlight, false);
  auto collect = [&](uint32_t slot) {
    const auto t = rec.stageTimes(slot);
    deform.push_back(t.deformMs), frames.push_back(t.tangentFramesMs), decode.push_back(t.vqDecodeMs);
    blend.push_back(t.normalBlendMs), total.push_back(t.totalMs);
  };
  std::vector<runtime::BlendedNormalMap> refMaps;
  runtime::ReferenceFrameOutputs lastRef;
  const float dt = 1.f / 30.f, alpha = 1.f - std::exp(-dt / model.temporalFilter.timeConstantSeconds);
  for (uint32_t f = 0; f < o.frames; ++f) {
    runtime::FrameKernelInputs in;
    in.instanceCount = o.characters;
    for (uint32_t c = 0; c < o.characters; ++c) {
      Pose pose = model.skeleton.restPose();
      for (size_t j = 1; j < pose.local.size(); ++j)
        pose.local[j] = Quatf(Eigen::AngleAxisf(0.4f * std::sin(0.2f * float(f) + float(c + j)), Vec3f::UnitZ()));
      pose.rootTranslation = Vec3f(float(c % 11) * 4.f - 20.f, 1.f, float(c / 11) * 10.f - 5.f);
      const auto mats = model.skeleton.skinningMatrices(pose);
      in.skinMatrices.insert(in.skinMatrices.end(), mats.begin(), mats.end());
      for (int k = 0; k < model.meshComponents(); ++k) in.meshWeights.push_back(float(rng.normal(0, 1.5)));
      if (!model.normalMaps.empty()) {
        in.selectedMaps.push_back(uint32_t((c + f / 10) % model.normalMaps.mapCount()) / 2);  // pairs share maps
        in.blendAlpha.push_back(f == 0 ? 1.f : alpha);
      }
    }
    const uint32_t slot = rec.slotOf(f);
    VkFence fence = fences[slot].get();
    SWISH_VK(vkWaitForFences(dev, 1, &fence, VK_TRUE, UINT64_MAX));
    if (slotUsed[slot]) collect(slot);
    SWISH_VK(vkResetFences(dev, 1, &fence));
    const auto t0 = std::chrono::steady_clock::now();
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    SWISH_VK(vkBeginCommandBuffer(cmds[slot], &bi));
    rec.record(cmds[slot], f, in);
    SWISH_VK(vkEndCommandBuffer(cmds[slot]));
    cpuRecord.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmds[slot];
    SWISH_VK(vkQueueSubmit(ctx.queue(), 1, &si, fence));
    slotUsed[slot] = true;
    lastRef = runtime::referenceFrame(model, in, refMaps);  // the CPU reference of the same frame
    refMaps = lastRef.normalMaps;
  }
  SWISH_VK(vkQueueWaitIdle(ctx.queue()));
  for (uint32_t k = 0; k < std::min(o.frames, o.framesInFlight); ++k) collect(rec.slotOf(o.frames - 1 - k));

  const auto gpu = rec.download(rec.slotOf(o.frames - 1));
  double posErr = 0, nrmErr = 0, tanErr = 0;
  int mapErr = 0;
  for (size_t i = 0; i < gpu.positions.size(); ++i) {
    posErr = std::max(
        posErr, maxAbsDiff(gpu.positions[i].data(), lastRef.positions[i].data(), size_t(gpu.positions[i].size())));
    nrmErr =
        std::max(nrmErr, maxAbsDiff(gpu.normals[i].data(), lastRef.normals[i].data(), size_t(gpu.normals[i].size())));
    tanErr = std::max(tanErr,
                      maxAbsDiff(gpu.tangents[i].data(), lastRef.tangents[i].data(), size_t(gpu.tangents[i].size())));
  }
  for (size_t i = 0; i < gpu.normalMaps.size(); ++i)
    for (size_t t = 0; t < gpu.normalMaps[i].xy.size(); ++t)
      mapErr = std::max(mapErr, std::abs(int(gpu.normalMaps[i].xy[t]) - int(lastRef.normalMaps[i].xy[t])));

  std::printf("\nper-frame GPU time (median over %zu frames, GPU timestamps):\n", total.size());
  std::printf("  deform (PCA + skinning, %u instances, 1 dispatch) %8.3f ms\n", o.characters, median(deform));
  std::printf("  normals + tangents                               %8.3f ms\n", median(frames));
  std::printf("  VQ decode (selected maps, each once)             %8.3f ms\n", median(decode));
  std::printf("  normal-map blend                                 %8.3f ms\n", median(blend));
  std::printf("  total                                            %8.3f ms  (%.1f us per character)\n", median(total),
              1e3 * median(total) / o.characters);
  std::printf("CPU recording time (median) %.3f ms\n", median(cpuRecord));
  std::printf(
      "\nlast frame, GPU vs CPU reference: positions %.3g mm, normals %.3g, tangents %.3g, normal maps %d snorm16 "
      "LSB\n",
      posErr * 1e3, nrmErr, tanErr, mapErr);
  const bool ok = posErr < 1e-3 && nrmErr < 1e-3 && tanErr < 1e-3 && mapErr <= 2;
  if (ctx.validationEnabled()) {
    std::printf("validation messages: %zu\n", ctx.validationMessageCount());
    for (const auto& m : ctx.validationMessages()) std::printf("  %s\n", m.c_str());
  }
  std::printf("%s\n", ok ? "OK" : "MISMATCH: the GPU outputs differ from the CPU reference");
  return ok && ctx.validationMessageCount() == 0 ? 0 : 1;
}

swish::cli::RunFn setup(CLI::App& app) {
  auto o = std::make_shared<FramesOptions>();
  app.add_option("--characters", o->characters, "Characters (instances of the model)")->check(CLI::Range(1u, 4096u));
  app.add_option("--frames", o->frames, "Frames to run")->check(CLI::Range(1u, 100000u));
  app.add_option("--vertices", o->vertices, "Vertices of the generated mesh")->check(CLI::Range(1u, 2000000u));
  app.add_option("--components", o->components, "Mesh PCA components K")->check(CLI::Range(1u, 256u));
  app.add_option("--maps", o->maps, "Normal maps in the generated database (0: none)")->check(CLI::Range(0u, 1024u));
  app.add_option("--map-size", o->mapSize, "Normal-map width and height (multiple of 4)")->check(CLI::Range(4u, 2048u));
  app.add_option("--frames-in-flight", o->framesInFlight, "Frames in flight")->check(CLI::Range(1u, 8u));
  app.add_option("--seed", o->seed, "Seed of the generated model and inputs");
  app.add_option("--device", o->device,
                 "Vulkan device: index or name substring (default: SWISH_DEVICE, else automatic)");
  app.add_flag("--validation", o->validation, "Enable the Vulkan validation layers (also SWISH_VALIDATION=1)");
  return [o]() { return run(*o); };
}

swish::cli::CommandRegistration reg{
    "frames", "Run a GPU frame loop of a generated model and check it against the CPU reference", setup};

}  // namespace
