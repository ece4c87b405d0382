#include "swish/gpu/frame_resources.hpp"

#include <algorithm>

#include "shaders/swish_layouts.h"
#include "swish/core/types.hpp"
#include "swish/gpu/allocation_plan.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/normal_map_blend_pass.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"

namespace swish::gpu {

namespace {

// The bytes of one frame in flight's buffers: the constructor allocates these and frameAllocations()
// lists them. Counts as GpuModel holds them (kernelComponents = max(K, 1)); 0 for what is not allocated.
struct FrameSizes {
  VkDeviceSize meshWeights = 0, instanceOrder = 0, skinMatrices = 0, positions = 0;
  VkDeviceSize normals = 0, tangents = 0, triangleTerms = 0;                      // with tangent frames
  VkDeviceSize decodeJobs = 0, blendCharacters = 0, decodedMaps = 0, texels = 0;  // with normal maps
  FrameSizes(uint32_t vertices, uint32_t triangles, uint32_t joints, uint32_t kernelComponents, uint32_t mapWidth,
             uint32_t mapHeight, uint32_t instances, bool frames, bool maps) {
    const VkDeviceSize n = vertices, c = std::max(1u, instances);
    meshWeights = DeformPass::weightsBytes(uint32_t(c), kernelComponents);
    instanceOrder = DeformPass::orderBytes(uint32_t(c));
    skinMatrices = std::max<VkDeviceSize>(16, DeformPass::skinMatricesBytes(uint32_t(c), joints));
    positions = c * n * 3 * sizeof(float);
    if (frames) {
      normals = c * n * 3 * sizeof(float);
      tangents = c * n * 4 * sizeof(float);
      triangleTerms = std::max<VkDeviceSize>(16, TangentFramesPass::triangleTermsBytes(triangles, uint32_t(c)));
    }
    if (maps) {
      decodeJobs = 2 * c * sizeof(uint32_t);
      blendCharacters = c * (sizeof(layout::NormalMapBlendCharacter) + sizeof(uint32_t));
      decodedMaps = c * mapWidth * mapHeight * 2;
      texels = NormalMapBlendPass::texelBytes(mapWidth, mapHeight, uint32_t(c));
    }
  }
};

}  // namespace

std::vector<Allocation> frameAllocations(const Model& m, uint32_t instances, bool frames, bool maps, bool shareTexels) {
  maps = maps && !m.normalMaps.empty();
  const FrameSizes z(uint32_t(m.gameMesh.vertexCount()), uint32_t(m.gameMesh.triangleCount()),
                     uint32_t(m.skeleton.size()), std::max(1u, uint32_t(m.meshComponents())), m.normalMaps.width,
                     m.normalMaps.height, instances, frames, maps);
  std::vector<Allocation> a;
  auto add = [&](const char* name, VkDeviceSize bytes, bool image = false) {
    a.push_back({name, bytes == 0 ? 4 : bytes, image});
  };
  add("mesh weights", z.meshWeights);
  add("instance order", z.instanceOrder);
  add("skin matrices", z.skinMatrices);
  add("positions", z.positions);
  if (frames) {
    add("normals", z.normals);
    add("tangents", z.tangents);
    add("triangle terms", z.triangleTerms);
  }
  if (maps) {
    add("decode jobs", z.decodeJobs);
    add("blend characters", z.blendCharacters);
    add("decoded maps", z.decodedMaps);
    // The images hold the blend's output (RG16 snorm, 4 bytes a texel); where the device cannot lay
    // them over a buffer, the blend writes a buffer of its own that is copied into them.
    add(shareTexels ? "normal maps (RG16 snorm array, linear: the blend's output)" : "normal maps (RG16 snorm array)",
        z.texels, true);
    if (!shareTexels) add("blended normal maps", z.texels);
  }
  return a;
}

FrameResources::FrameResources(Context& ctx, const GpuModel& m, uint32_t cap, bool withFrames, bool withMaps,
                               uint32_t slot, bool shareTexels) {
  const std::string tag = m.name() + " frame " + std::to_string(slot) + ": ";
  const FrameSizes z(m.vertexCount(), m.triangleCount(), m.jointCount(), m.kernelMeshComponents(), m.mapWidth(),
                     m.mapHeight(), cap, withFrames, withMaps);
  const uint32_t c = std::max(1u, cap);
  meshWeights = Buffer(ctx, z.meshWeights, MemoryKind::HostVisible, tag + "mesh weights");
  instanceOrder = Buffer(ctx, z.instanceOrder, MemoryKind::HostVisible, tag + "instance order");
  skinMatrices = Buffer(ctx, z.skinMatrices, MemoryKind::HostVisible, tag + "skin matrices");
  positions = Buffer(ctx, z.positions, MemoryKind::DeviceLocal, tag + "positions");
  if (withFrames) {
    normals = Buffer(ctx, z.normals, MemoryKind::DeviceLocal, tag + "normals");
    tangents = Buffer(ctx, z.tangents, MemoryKind::DeviceLocal, tag + "tangents");
    triangleTerms = Buffer(ctx, z.triangleTerms, MemoryKind::DeviceLocal, tag + "triangle terms");
  }
  if (withMaps) {
    decodeSlotMaps = Buffer(ctx, z.decodeJobs, MemoryKind::HostVisible, tag + "decode jobs");
    blendCharacters = Buffer(ctx, z.blendCharacters, MemoryKind::HostVisible, tag + "blend characters");
    decodedMaps = Buffer(ctx, z.decodedMaps, MemoryKind::DeviceLocal, tag + "decoded maps");
    normalMaps = NormalMapImages(ctx, m.mapWidth(), m.mapHeight(), c, shareTexels);
    if (!normalMaps.sharesTexels())
      blendedTexels = Buffer(ctx, z.texels, MemoryKind::DeviceLocal, tag + "blended normal maps");
    // The blend's state starts as the images do: all 0.
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      vkCmdFillBuffer(cmd, blendOutput().handle(), 0, VK_WHOLE_SIZE, 0);
      VkMemoryBarrier mb{};
      mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
      mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0,
                           nullptr, 0, nullptr);
    });
    slotMap.assign(c, kNoMap);
    slotLastUsed.assign(c, 0);
    layerVersion.assign(c, 0);  // version 0: all zeros, as the images start
  }
  timestamps = TimestampQueries(ctx, 5);
}

}  // namespace swish::gpu
