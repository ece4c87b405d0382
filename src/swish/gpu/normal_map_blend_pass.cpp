#include "swish/gpu/normal_map_blend_pass.hpp"

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <utility>
#include <vector>

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

static_assert(sizeof(NormalMapBlendPass::Character) == sizeof(layout::NormalMapBlendCharacter) &&
              offsetof(NormalMapBlendPass::Character, alpha) == offsetof(layout::NormalMapBlendCharacter, alpha));

NormalMapBlendPass::NormalMapBlendPass(Context& ctx, uint32_t width, bool store64)
    : width_(width),
      store64_(store64 && ctx.hasShaderInt64()),
      layout_(ctx, {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER}) {
  if (width == 0 || width % 4)
    throw Error("normal-map blend: map width " + std::to_string(width) + " is not a multiple of 4");
  const VkPhysicalDeviceLimits& lim = ctx.properties().limits;
  const uint32_t blocksX = width / 4;
  const uint32_t most = std::min({kMaxRowGroup, lim.maxComputeWorkGroupSize[0], lim.maxComputeWorkGroupInvocations});
  for (uint32_t d = std::min(most, blocksX); d >= kMinRowGroup && !exact_; --d)
    if (blocksX % d == 0) rowGroup_ = d, exact_ = true;
  if (!exact_) rowGroup_ = std::min(kFallbackGroup, most);
  for (size_t i = 0; i < std::size(kRowsPerInvocation); ++i)
    pipelines_[i] = ComputePipeline(ctx, store64_ ? "normal_map_blend_store64.comp" : "normal_map_blend.comp",
                                    {rowGroup_, exact_ ? 1u : 0u, kRowsPerInvocation[i]},
                                    sizeof(layout::NormalMapBlendParams), layout_.get());
}

DescriptorBinding NormalMapBlendPass::makeBinding(Context& ctx, const Buffer& prev, const Buffer& out,
                                                  const Buffer& decoded) const {
  return DescriptorBinding(ctx, layout_,
                           {BoundResource::texels(prev, VK_FORMAT_R32G32B32A32_UINT), BoundResource::storage(out),
                            BoundResource::texels(decoded, VK_FORMAT_R32G32_UINT)});
}

uint32_t NormalMapBlendPass::record(VkCommandBuffer cmd, VkDescriptorSet binding, const Args& a) const {
  if (a.characterCount == 0 || a.width == 0 || a.height == 0) return 0;
  if (a.width != width_ || a.height % 4)
    throw Error("normal-map blend: map size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " is not a multiple of 4 or not the pass's width " + std::to_string(width_));
  if (a.outTexels == VK_NULL_HANDLE || a.outMaps == VK_NULL_HANDLE)
    throw Error("normal-map blend: no output buffer or images to copy the blended maps into");
  std::vector<uint32_t> sorted(a.hostLayers.begin(), a.hostLayers.end());  // the layers written, ascending
  std::sort(sorted.begin(), sorted.end());
  if (a.layers) {
    if (sorted.size() != a.characterCount)
      throw Error("normal-map blend: " + std::to_string(sorted.size()) + " host layers for " +
                  std::to_string(a.characterCount) + " characters");
    for (size_t i = 0; i < sorted.size(); ++i) {
      if (sorted[i] >= a.maxLayers)
        throw Error("normal-map blend: layer " + std::to_string(sorted[i]) + " of " + std::to_string(a.maxLayers));
      if (i > 0 && sorted[i] == sorted[i - 1])
        throw Error("normal-map blend: layer " + std::to_string(sorted[i]) + " given to two characters");
    }
  }
  layout::NormalMapBlendParams p;
  p.characters = layout::Address::of(a.characters);
  p.layers = layout::Address::of(a.layers);
  p.width = a.width;
  p.height = a.height;
  p.characterCount = a.characterCount;
  p.pad0 = 0;
  size_t which = 0;
  while (a.height % kRowsPerInvocation[which]) ++which;  // stops at 4 at the latest: checked above
  pipelines_[which].bind(cmd, &p, sizeof(p), binding);
  vkCmdDispatch(cmd, groupCount(a.width / 4, rowGroup_), a.height / kRowsPerInvocation[which], a.characterCount);

  if (a.outMapsShareTexels) {  // the dispatch wrote the images' memory: make it available (see the header)
    computeToComputeBarrier(cmd);
    return 1;
  }
  // The blended texels, written by the dispatch, are read by the copy. The images' layers go to
  // TRANSFER_DST_OPTIMAL for the copy (the layout copies ask for) and back to GENERAL; the first barrier
  // also orders the copy's image writes after every earlier access to the images on this queue (all
  // ordered before the dispatch).
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkImageMemoryBarrier ib{};
  ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  ib.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  ib.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
  ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  // The layers written, as runs of consecutive layers: one copy region (and barrier range) per run.
  std::vector<std::pair<uint32_t, uint32_t>> runs;  // first layer, count
  if (!a.layers) {
    runs.emplace_back(0, a.characterCount);
  } else {
    for (uint32_t layer : sorted)
      if (!runs.empty() && runs.back().first + runs.back().second == layer)
        ++runs.back().second;
      else
        runs.emplace_back(layer, 1);
  }
  ib.image = a.outMaps;
  std::vector<VkImageMemoryBarrier> ibs(runs.size(), ib);
  std::vector<VkBufferImageCopy> copies(runs.size());
  const VkDeviceSize layerBytes = texelBytes(a.width, a.height, 1);
  for (size_t r = 0; r < runs.size(); ++r) {
    ibs[r].subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, runs[r].first, runs[r].second};
    VkBufferImageCopy& c = copies[r];  // tightly packed rows and layers: the texels' layout is the image's
    c.bufferOffset = runs[r].first * layerBytes;
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, runs[r].first, runs[r].second};
    c.imageExtent = {a.width, a.height, 1};
  }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr,
                       uint32_t(ibs.size()), ibs.data());
  vkCmdCopyBufferToImage(cmd, a.outTexels, a.outMaps, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(copies.size()),
                         copies.data());
  // Back to GENERAL and to the compute stage, so that a consumer's barrier from
  // COMPUTE_SHADER/SHADER_WRITE (the contract of FrameRecorder and of the public API) chains to the
  // copy's writes.
  for (VkImageMemoryBarrier& b : ibs) {
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
  }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                       nullptr, uint32_t(ibs.size()), ibs.data());
  return 1;
}

}  // namespace swish::gpu
