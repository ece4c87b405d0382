#pragma once
// The preview renderer's Vulkan objects: buffers and images with their own memory, owned RAII-style.
// The renderer is a host like any other (its own instance and graphics device), so it does not use the
// library's gpu::Context; it shares the gpu layer's device-free pieces instead: the handle owner below
// and the queries of gpu/vk_helpers.hpp (layers, queue families, memory types, device choice).
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/vk_unique.hpp"

namespace swish::render {

class HostDevice;

// Any handle with a destroy function; move-only. The gpu layer's header-only owner (it pulls in
// nothing else of that layer).
template <class H>
using Owned = gpu::VkUnique<H>;

// A buffer in host-visible, coherent memory, mapped for its lifetime (vertex data written each frame,
// image readback). The preview moves little data; one allocation per buffer is plenty.
struct MappedBuffer {
  Owned<VkBuffer> buffer;
  Owned<VkDeviceMemory> memory;
  void* data = nullptr;
  VkDeviceSize size = 0;
};
MappedBuffer makeMappedBuffer(HostDevice& device, VkDeviceSize size, VkBufferUsageFlags usage);

// A 2D device-local image with one view.
struct OwnedImage {
  Owned<VkImage> image;
  Owned<VkDeviceMemory> memory;
  Owned<VkImageView> view;
};
OwnedImage makeImage(HostDevice& device, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                     VkImageAspectFlags aspect, VkImageViewType viewType = VK_IMAGE_VIEW_TYPE_2D);

// Throws api::Error(VulkanFailure) naming the call.
void vkCheck(VkResult r, const char* call);

}  // namespace swish::render
