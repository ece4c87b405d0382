#include "swish/gpu/frame_resources.hpp"

#include <algorithm>

#include "shaders/swish_layouts.h"
#include "swish/core/types.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/normal_map_blend_pass.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"

namespace swish::gpu {

FrameResources::FrameResources(Context& ctx, const GpuModel& m, uint32_t cap, bool withFrames, bool withMaps,
                               uint32_t slot, bool shareTexels) {
  const std::string tag = m.name() + " frame " + std::to_string(slot) + ": ";
  const VkDeviceSize n = m.vertexCount(), c = std::max(1u, cap);
  meshWeights = Buffer(ctx, DeformPass::weightsBytes(uint32_t(c), m.kernelMeshComponents()), MemoryKind::HostVisible,
                       tag + "mesh weights");
  instanceOrder = Buffer(ctx, DeformPass::orderBytes(uint32_t(c)), MemoryKind::HostVisible, tag + "instance order");
  skinMatrices = Buffer(ctx, std::max<VkDeviceSize>(16, DeformPass::skinMatricesBytes(uint32_t(c), m.jointCount())),
                        MemoryKind::HostVisible, tag + "skin matrices");
  if (m.capsuleCount() > 0)
    posedCapsules =
        Buffer(ctx, c * m.capsuleCount() * 8 * sizeof(float), MemoryKind::HostVisible, tag + "posed capsules");
  positions = Buffer(ctx, c * n * 3 * sizeof(float), MemoryKind::DeviceLocal, tag + "positions");
  if (withFrames) {
    normals = Buffer(ctx, c * n * 3 * sizeof(float), MemoryKind::DeviceLocal, tag + "normals");
    tangents = Buffer(ctx, c * n * 4 * sizeof(float), MemoryKind::DeviceLocal, tag + "tangents");
    triangleTerms =
        Buffer(ctx, std::max<VkDeviceSize>(16, TangentFramesPass::triangleTermsBytes(m.triangleCount(), uint32_t(c))),
               MemoryKind::DeviceLocal, tag + "triangle terms");
  }
  if (withMaps) {
    decodeSlotMaps = Buffer(ctx, 2 * c * sizeof(uint32_t), MemoryKind::HostVisible, tag + "decode jobs");
    blendCharacters = Buffer(ctx, c * (sizeof(layout::NormalMapBlendCharacter) + sizeof(uint32_t)),
                             MemoryKind::HostVisible, tag + "blend characters");
    decodedMaps = Buffer(ctx, c * m.mapWidth() * m.mapHeight() * 2, MemoryKind::DeviceLocal, tag + "decoded maps");
    normalMaps = NormalMapImages(ctx, m.mapWidth(), m.mapHeight(), uint32_t(c), shareTexels);
    if (!normalMaps.sharesTexels())
      blendedTexels = Buffer(ctx, NormalMapBlendPass::texelBytes(m.mapWidth(), m.mapHeight(), uint32_t(c)),
                             MemoryKind::DeviceLocal, tag + "blended normal maps");
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
