#include "swish/gpu/buffer.hpp"

#include "swish/gpu/context.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

Buffer::Buffer(Context& ctx, VkDeviceSize size, MemoryKind kind, const std::string& name) : name_(name) {
  device_ = ctx.device();
  size_ = size == 0 ? 4 : size;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size_;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
              VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
              VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer b;
  SWISH_VK(vkCreateBuffer(device_, &bci, nullptr, &b));
  VkDevice dev = device_;
  buffer_ = VkUnique<VkBuffer>(b, [dev](VkBuffer h) { vkDestroyBuffer(dev, h, nullptr); });

  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b, &req);
  const VkMemoryPropertyFlags hostFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  const uint32_t type = kind == MemoryKind::HostVisible
                            ? ctx.memoryType(req.memoryTypeBits, hostFlags, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)
                            : ctx.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, hostFlags);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VkDeviceMemory mem;
  const VkResult r = vkAllocateMemory(device_, &mai, nullptr, &mem);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw Error("out of memory allocating " + std::to_string(size_) + " bytes for buffer '" + name_ + "'");
  if (r != VK_SUCCESS) throwVkError(r, "vkAllocateMemory", __FILE__, __LINE__);
  memory_ = VkUnique<VkDeviceMemory>(mem, [dev](VkDeviceMemory h) { vkFreeMemory(dev, h, nullptr); });
  SWISH_VK(vkBindBufferMemory(device_, b, mem, 0));

  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mp);
  const VkMemoryPropertyFlags got = mp.memoryTypes[type].propertyFlags;
  if ((got & hostFlags) == hostFlags) SWISH_VK(vkMapMemory(device_, mem, 0, VK_WHOLE_SIZE, 0, &mapped_));

  VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  ai.buffer = b;
  address_ = vkGetBufferDeviceAddress(device_, &ai);
}

namespace {
void checkRange(const std::string& name, VkDeviceSize size, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset > size || bytes > size - offset)
    throw Error("buffer '" + name + "': access of " + std::to_string(bytes) + " bytes at offset " + std::to_string(offset) +
                " exceeds its size " + std::to_string(size));
}
}  // namespace

void Buffer::upload(Context& ctx, const void* src, VkDeviceSize bytes, VkDeviceSize offset) {
  checkRange(name_, size_, bytes, offset);
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, src, bytes);
    return;
  }
  Buffer staging(ctx, bytes, MemoryKind::HostVisible, name_ + " (staging)");
  std::memcpy(staging.data(), src, bytes);
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy c{0, offset, bytes};
    vkCmdCopyBuffer(cmd, staging.handle(), handle(), 1, &c);
  });
}

void Buffer::download(Context& ctx, void* dst, VkDeviceSize bytes, VkDeviceSize offset) const {
  checkRange(name_, size_, bytes, offset);
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(dst, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(ctx, bytes, MemoryKind::HostVisible, name_ + " (readback)");
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy c{offset, 0, bytes};
    vkCmdCopyBuffer(cmd, handle(), staging.handle(), 1, &c);
  });
  std::memcpy(dst, staging.data(), bytes);
}

void computeToComputeBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0,
                       nullptr, 0, nullptr);
}

void computeToHostBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

}  // namespace swish::gpu
