// The barriers a renderer records between swish's passes and its own reads of their outputs.
#include "swish/api_types.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"  // Vulkan structs: other members zero on purpose

namespace swish::api {

namespace {
// Same family (or none named): a plain memory dependency. Different: an ownership transfer.
void setFamilies(uint32_t owner, uint32_t dst, uint32_t& srcOut, uint32_t& dstOut) {
  if (dst == VK_QUEUE_FAMILY_IGNORED || dst == owner) {
    srcOut = dstOut = VK_QUEUE_FAMILY_IGNORED;
  } else {
    srcOut = owner;
    dstOut = dst;
  }
}
}  // namespace

std::vector<VkBufferMemoryBarrier2> FrameOutputs::vertexBarriers(uint32_t dstQueueFamily,
                                                                 VkPipelineStageFlags2 dstStage,
                                                                 VkAccessFlags2 dstAccess) const {
  std::vector<VkBufferMemoryBarrier2> out;
  for (const VertexStream* s : {&positions, &normals, &tangents}) {
    if (s->buffer == VK_NULL_HANDLE) continue;
    VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    b.srcStageMask = kSrcStage;
    b.srcAccessMask = kSrcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    setFamilies(queueFamily, dstQueueFamily, b.srcQueueFamilyIndex, b.dstQueueFamilyIndex);
    b.buffer = s->buffer;
    b.offset = 0;
    b.size = VK_WHOLE_SIZE;
    out.push_back(b);
  }
  return out;
}

std::optional<VkImageMemoryBarrier2> FrameOutputs::normalMapBarrier(uint32_t dstQueueFamily,
                                                                    VkPipelineStageFlags2 dstStage,
                                                                    VkAccessFlags2 dstAccess) const {
  if (!normalMaps) return std::nullopt;
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = kSrcStage;
  b.srcAccessMask = kSrcAccess;
  b.dstStageMask = dstStage;
  b.dstAccessMask = dstAccess;
  b.oldLayout = normalMaps->layout;  // no transition: swish keeps the image in GENERAL
  b.newLayout = normalMaps->layout;
  setFamilies(queueFamily, dstQueueFamily, b.srcQueueFamilyIndex, b.dstQueueFamilyIndex);
  b.image = normalMaps->image;
  b.subresourceRange = normalMaps->range;
  return b;
}

}  // namespace swish::api
