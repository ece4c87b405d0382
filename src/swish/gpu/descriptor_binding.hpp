#pragma once
// Descriptor sets for the per-instance data of the frame passes: texel buffers (read), storage buffers
// (written) and storage images, bound once to the buffers of one frame in flight and reused every frame.
//
// Why not buffer addresses for everything: lavapipe (Mesa 22.3), the CPU device the benchmarks run on,
// loads through a buffer address one lane at a time and one component at a time (a loop per
// component), while a texel fetch of a whole vec4 is one gather, and a vec4 store into a storage
// buffer costs about half one through an address (figures: docs/performance.md). The per-instance streams (mesh
// weights, skin matrices, deformed positions, triangle terms, the adjacency walked per instance,
// decoded maps) are therefore read as texel buffers and the vec4 outputs written through storage
// buffers; model data read once per frame keeps its address, except the deform's PCA basis, the
// largest (3K loads per vertex), which it fetches as texels where the device's limits allow. On GPUs
// texel buffers are an ordinary, cached path, so nothing is lost there.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Buffer;
class Context;

// One binding of a set: what a DescriptorBinding binds at that index.
struct BoundResource {
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  const Buffer* buffer = nullptr;
  VkFormat format = VK_FORMAT_UNDEFINED;  // texel buffers
  VkDeviceSize offset = 0;
  VkDeviceSize range = VK_WHOLE_SIZE;  // texel buffers: whole texels of the rest of the buffer
  VkImageView image = VK_NULL_HANDLE;  // storage images (layout GENERAL)

  // A uniform texel buffer (GLSL samplerBuffer / usamplerBuffer) over `buffer` from `offset`.
  static BoundResource texels(const Buffer& buffer, VkFormat format, VkDeviceSize offset = 0,
                              VkDeviceSize range = VK_WHOLE_SIZE);
  // A storage buffer (GLSL buffer block) over `buffer` from `offset`.
  static BoundResource storage(const Buffer& buffer, VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE);
  static BoundResource storageImage(VkImageView view);
};

// A descriptor set layout: binding i has type types[i], visible to compute shaders.
class DescriptorLayout {
 public:
  DescriptorLayout() = default;
  DescriptorLayout(Context& ctx, std::vector<VkDescriptorType> types);
  VkDescriptorSetLayout get() const { return layout_.get(); }
  const std::vector<VkDescriptorType>& types() const { return types_; }

 private:
  std::vector<VkDescriptorType> types_;
  VkUnique<VkDescriptorSetLayout> layout_;
};

// One descriptor set of a DescriptorLayout with its own small pool and the buffer views it needs. The
// bound buffers must outlive it (and every submission that uses it).
class DescriptorBinding {
 public:
  DescriptorBinding() = default;
  // Throws Error when a resource does not match its binding's type, or a texel view is empty, misaligned
  // or beyond the device's maxTexelBufferElements.
  DescriptorBinding(Context& ctx, const DescriptorLayout& layout, const std::vector<BoundResource>& resources);
  DescriptorBinding(DescriptorBinding&& o) noexcept;
  DescriptorBinding& operator=(DescriptorBinding&& o) noexcept;
  VkDescriptorSet get() const { return set_; }
  explicit operator bool() const { return set_ != VK_NULL_HANDLE; }

 private:
  VkUnique<VkDescriptorPool> pool_;  // freeing the pool frees the set
  std::vector<VkUnique<VkBufferView>> views_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

}  // namespace swish::gpu
