#include "swish/gpu/normal_map_images.hpp"

#include <algorithm>

#include "swish/gpu/context.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

namespace {
// The usage the header and docs/integration.md promise: storage, sampled, transfer src/dst.
constexpr VkImageUsageFlags kUsage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
}  // namespace

bool NormalMapImages::deviceSupportsLinear(Context& ctx, uint32_t width, uint32_t height, uint32_t layers) {
  constexpr VkFormatFeatureFlags features = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT |
                                            VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), kFormat, &fp);
  if ((fp.linearTilingFeatures & features) != features) return false;
  VkImageFormatProperties ip;
  if (vkGetPhysicalDeviceImageFormatProperties(ctx.physicalDevice(), kFormat, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_LINEAR,
                                               kUsage, 0, &ip) != VK_SUCCESS)
    return false;
  return ip.maxArrayLayers >= layers && ip.maxExtent.width >= width && ip.maxExtent.height >= height &&
         ip.maxResourceSize >= VkDeviceSize(width) * height * 4 * layers;
}

NormalMapImages::NormalMapImages(Context& ctx, uint32_t width, uint32_t height, uint32_t layers, bool shareTexels)
    : width_(width), height_(height), layers_(layers) {
  if (!ctx.supportsNormalMaps())
    throw Error(
        "Vulkan device '" + ctx.deviceName() +
        "' cannot store normal maps: it lacks storage images of R16G16_SNORM (shaderStorageImageExtendedFormats)");
  if (width == 0 || height == 0 || layers == 0) throw Error("normal-map images: width, height and layers must be > 0");
  const VkDevice dev = ctx.device();
  const VkDeviceSize texelBytes = VkDeviceSize(width) * height * 4 * layers;
  auto createImage = [&](VkImageTiling tiling) {
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = kFormat;
    ici.extent = {width, height, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = layers;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = tiling;
    ici.usage = kUsage;
    ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImage img;
    SWISH_VK(vkCreateImage(dev, &ici, nullptr, &img));
    image_ = VkUnique<VkImage>(img, [dev](VkImage h) { vkDestroyImage(dev, h, nullptr); });
  };
  // Shared texels need a linear image whose layers lie exactly as the packed texels do.
  auto tightlyPacked = [&] {
    for (uint32_t l = 0; l < layers; ++l) {
      const VkImageSubresource sub{VK_IMAGE_ASPECT_COLOR_BIT, 0, l};
      VkSubresourceLayout sl;
      vkGetImageSubresourceLayout(dev, image_.get(), &sub, &sl);
      if (sl.offset != VkDeviceSize(l) * width * height * 4 || sl.rowPitch != VkDeviceSize(width) * 4 ||
          (layers > 1 && sl.arrayPitch != VkDeviceSize(width) * height * 4))
        return false;
    }
    return true;
  };
  bool shared = false;
  if (shareTexels && deviceSupportsLinear(ctx, width, height, layers)) {
    createImage(VK_IMAGE_TILING_LINEAR);
    shared = tightlyPacked();
    if (!shared) image_.reset();
  }
  if (!shared) createImage(VK_IMAGE_TILING_OPTIMAL);

  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(dev, image_.get(), &req);
  VkDeviceSize bytes = req.size;
  uint32_t typeBits = req.memoryTypeBits;
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  if (shared) {  // the memory also holds the texel buffer (which has a device address)
    const VkMemoryRequirements breq = Buffer::requirements(ctx, texelBytes);
    bytes = std::max(bytes, breq.size);
    typeBits &= breq.memoryTypeBits;
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  }
  const uint32_t type = ctx.memoryType(typeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, shared ? &flags : nullptr};
  mai.allocationSize = bytes;
  mai.memoryTypeIndex = type;
  VkDeviceMemory mem;
  SWISH_VK(vkAllocateMemory(dev, &mai, nullptr, &mem));
  memory_ = VkUnique<VkDeviceMemory>(mem, [dev](VkDeviceMemory h) { vkFreeMemory(dev, h, nullptr); });
  SWISH_VK(vkBindImageMemory(dev, image_.get(), mem, 0));
  if (shared) texels_ = Buffer(ctx, texelBytes, mem, type, bytes, "normal maps (shared texels)");
  const VkImage img = image_.get();
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vci.format = kFormat;
  vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
  VkImageView view;
  SWISH_VK(vkCreateImageView(dev, &vci, nullptr, &view));
  view_ = VkUnique<VkImageView>(view, [dev](VkImageView h) { vkDestroyImageView(dev, h, nullptr); });

  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = 0;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img;
    b.subresourceRange = vci.subresourceRange;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    const VkClearColorValue zero{};
    vkCmdClearColorImage(cmd, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &vci.subresourceRange);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
  });
}

namespace {
// Layout transitions around transfers: the images live in GENERAL, copies use the TRANSFER_*_OPTIMAL
// layouts (what the validation layers' best-practice checks ask for).
void transition(VkCommandBuffer cmd, VkImage image, uint32_t layers, VkImageLayout from, VkImageLayout to,
                VkAccessFlags src, VkPipelineStageFlags srcStage, VkAccessFlags dst, VkPipelineStageFlags dstStage) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}
constexpr VkAccessFlags kShaderRW = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
}  // namespace

std::vector<int16_t> NormalMapImages::download(Context& ctx) const {
  const size_t count = size_t(width_) * height_ * layers_ * 2;
  if (sharesTexels()) {  // the texels are the image's memory, laid out as download's result
    ctx.submitAndWait([](VkCommandBuffer cmd) {
      VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
      mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                           nullptr);
    });
    std::vector<int16_t> out(count);
    texels_.download(ctx, out.data(), count * sizeof(int16_t));
    return out;
  }
  Buffer staging(ctx, count * sizeof(int16_t), MemoryKind::HostVisible, "normal-map readback");
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    transition(cmd, image(), layers_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, layers_};
    c.imageExtent = {width_, height_, 1};
    vkCmdCopyImageToBuffer(cmd, image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1, &c);
    transition(cmd, image(), layers_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
               VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, kShaderRW,
               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    computeToHostBarrier(cmd);
  });
  std::vector<int16_t> out(count);
  std::memcpy(out.data(), staging.data(), count * sizeof(int16_t));
  return out;
}

void NormalMapImages::upload(Context& ctx, const std::vector<int16_t>& texels) {
  const size_t count = size_t(width_) * height_ * layers_ * 2;
  if (texels.size() != count)
    throw Error("normal-map upload: " + std::to_string(texels.size()) + " values given, " + std::to_string(count) +
                " expected");
  if (sharesTexels()) {
    texels_.upload(ctx, texels.data(), count * sizeof(int16_t));
    return;
  }
  Buffer staging(ctx, count * sizeof(int16_t), MemoryKind::HostVisible, "normal-map upload");
  std::memcpy(staging.data(), texels.data(), count * sizeof(int16_t));
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    transition(cmd, image(), layers_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, kShaderRW,
               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, layers_};
    c.imageExtent = {width_, height_, 1};
    vkCmdCopyBufferToImage(cmd, staging.handle(), image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    transition(cmd, image(), layers_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, kShaderRW,
               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  });
}

}  // namespace swish::gpu
