#pragma once
// The per-character normal maps of one frame in flight: a 2D array image, one layer per character,
// format VK_FORMAT_R16G16_SNORM (tangent-space X and Y; renderers reconstruct Z as
// sqrt(max(0, 1 - X^2 - Y^2))). Why RG16_SNORM: the temporal filter accumulates small steps every
// frame, which 8 bits would stall and half floats would round coarsely near +-1; it is a storage
// format lavapipe and desktop GPUs support (checked: Context::supportsNormalMaps). 2 channels keep
// 360x360 maps at 0.5 MB per character.
//
// Shared texels (shareTexels, where the device allows it): the image is LINEAR-tiled, its layers lie
// tightly packed (row pitch 4 * width, layer pitch rows * height, checked with
// vkGetImageSubresourceLayout) and a storage buffer, texels(), lies over the same memory: the
// uint32[layer][height][width] packed texels (snorm16 X | Y << 16) the blend pass writes. The blend
// then writes the maps renderers sample, with no copy into the image (bench_replay: see
// normal_map_blend_pass.hpp). Lavapipe (and unified-memory devices that sample linear 2D arrays)
// allow it; where the device does not sample linear 2D-array images of this format, or lays them out
// with padding, the image is OPTIMAL-tiled with memory of its own and sharesTexels() is false.
//
// Layout: VK_IMAGE_LAYOUT_GENERAL for its whole life (set at creation, contents cleared to 0).
// Usage: storage, sampled (the host renderer), transfer src/dst (the blend pass's copy of its result,
// readback, clears). A renderer sampling it after swish's blend pass needs a barrier: compute shader
// write -> its own stage's shader read, on the queue family of the Context (the blend pass ends its
// copy with a barrier to the compute stage, so that this barrier covers the copy's writes).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "swish/gpu/buffer.hpp"
#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Context;

class NormalMapImages {
 public:
  static constexpr VkFormat kFormat = VK_FORMAT_R16G16_SNORM;

  NormalMapImages() = default;
  NormalMapImages(Context& ctx, uint32_t width, uint32_t height, uint32_t layers, bool shareTexels = false);

  // Whether the device samples and stores LINEAR-tiled 2D arrays of kFormat of this size (the first
  // condition of shared texels; the constructor checks the layout too).
  static bool deviceSupportsLinear(Context& ctx, uint32_t width, uint32_t height, uint32_t layers);
  bool sharesTexels() const { return static_cast<bool>(texels_.handle()); }
  // The packed texels over the image's memory (only where sharesTexels()).
  const Buffer& texels() const { return texels_; }

  VkImage image() const { return image_.get(); }
  VkImageView arrayView() const { return view_.get(); }  // all layers, for the blend pass
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  uint32_t layers() const { return layers_; }

  // Reads every layer back as int16 pairs (X, Y), layer-major then row-major. Waits.
  std::vector<int16_t> download(Context& ctx) const;
  // Overwrites every layer (same layout as download). Waits.
  void upload(Context& ctx, const std::vector<int16_t>& texels);

 private:
  VkUnique<VkImage> image_;
  VkUnique<VkDeviceMemory> memory_;
  VkUnique<VkImageView> view_;
  Buffer texels_;  // over memory_ (declared after it: destroyed first); empty unless sharesTexels()
  uint32_t width_ = 0, height_ = 0, layers_ = 0;
};

}  // namespace swish::gpu
