#include "swish/render/vk_owned.hpp"

#include <string>

#include "swish/api_error.hpp"
#include "swish/render/host_device.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace swish::render {

void vkCheck(VkResult r, const char* call) {
  if (r != VK_SUCCESS)
    throw api::Error(api::ErrorCode::VulkanFailure,
                     std::string("preview renderer: ") + call + " returned " + std::to_string(int(r)));
}

MappedBuffer makeMappedBuffer(HostDevice& d, VkDeviceSize size, VkBufferUsageFlags usage) {
  VkDevice dev = d.device();
  MappedBuffer b;
  b.size = size == 0 ? 4 : size;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = b.size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buf;
  vkCheck(vkCreateBuffer(dev, &bci, nullptr, &buf), "vkCreateBuffer");
  b.buffer = Owned<VkBuffer>(buf, [dev](VkBuffer h) { vkDestroyBuffer(dev, h, nullptr); });
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buf, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex =
      d.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkDeviceMemory mem;
  vkCheck(vkAllocateMemory(dev, &mai, nullptr, &mem), "vkAllocateMemory");
  b.memory = Owned<VkDeviceMemory>(mem, [dev](VkDeviceMemory h) { vkFreeMemory(dev, h, nullptr); });
  vkCheck(vkBindBufferMemory(dev, buf, mem, 0), "vkBindBufferMemory");
  vkCheck(vkMapMemory(dev, mem, 0, VK_WHOLE_SIZE, 0, &b.data), "vkMapMemory");
  return b;
}

OwnedImage makeImage(HostDevice& d, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                     VkImageAspectFlags aspect, VkImageViewType viewType) {
  VkDevice dev = d.device();
  OwnedImage img;
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {width, height, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage image;
  vkCheck(vkCreateImage(dev, &ici, nullptr, &image), "vkCreateImage");
  img.image = Owned<VkImage>(image, [dev](VkImage h) { vkDestroyImage(dev, h, nullptr); });
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(dev, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = d.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkDeviceMemory mem;
  vkCheck(vkAllocateMemory(dev, &mai, nullptr, &mem), "vkAllocateMemory");
  img.memory = Owned<VkDeviceMemory>(mem, [dev](VkDeviceMemory h) { vkFreeMemory(dev, h, nullptr); });
  vkCheck(vkBindImageMemory(dev, image, mem, 0), "vkBindImageMemory");
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = image;
  vci.viewType = viewType;
  vci.format = format;
  vci.subresourceRange = {aspect, 0, 1, 0, 1};
  VkImageView view;
  vkCheck(vkCreateImageView(dev, &vci, nullptr, &view), "vkCreateImageView");
  img.view = Owned<VkImageView>(view, [dev](VkImageView h) { vkDestroyImageView(dev, h, nullptr); });
  return img;
}

}  // namespace swish::render
