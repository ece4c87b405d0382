#include "swish/gpu/buffer.hpp"

#include "swish/gpu/context.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

namespace {
constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                      VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
                                      VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
VkBufferCreateInfo createInfo(VkDeviceSize size) {
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size == 0 ? 4 : size;
  bci.usage = kUsage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  return bci;
}
}  // namespace

VkMemoryRequirements Buffer::requirements(Context& ctx, VkDeviceSize size) {
  const VkBufferCreateInfo bci = createInfo(size);
  VkDeviceBufferMemoryRequirements info{VK_STRUCTURE_TYPE_DEVICE_BUFFER_MEMORY_REQUIREMENTS};
  info.pCreateInfo = &bci;
  VkMemoryRequirements2 req{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
  vkGetDeviceBufferMemoryRequirements(ctx.device(), &info, &req);
  return req.memoryRequirements;
}

void Buffer::createHandle(Context& ctx) {
  device_ = ctx.device();
  size_ = size_ == 0 ? 4 : size_;
  const VkBufferCreateInfo bci = createInfo(size_);
  VkBuffer b;
  SWISH_VK(vkCreateBuffer(device_, &bci, nullptr, &b));
  VkDevice dev = device_;
  buffer_ = VkUnique<VkBuffer>(b, [dev](VkBuffer h) { vkDestroyBuffer(dev, h, nullptr); });
}

void Buffer::finish(Context& ctx, VkDeviceMemory mem, uint32_t type) {
  SWISH_VK(vkBindBufferMemory(device_, handle(), mem, 0));
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mp);
  const VkMemoryPropertyFlags hostFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  if ((mp.memoryTypes[type].propertyFlags & hostFlags) == hostFlags)
    SWISH_VK(vkMapMemory(device_, mem, 0, VK_WHOLE_SIZE, 0, &mapped_));
  VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  ai.buffer = handle();
  address_ = vkGetBufferDeviceAddress(device_, &ai);
}

Buffer::Buffer(Context& ctx, VkDeviceSize size, MemoryKind kind, const std::string& name) : size_(size), name_(name) {
  createHandle(ctx);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, handle(), &req);
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
  VkDevice dev = device_;
  memory_ = VkUnique<VkDeviceMemory>(mem, [dev](VkDeviceMemory h) { vkFreeMemory(dev, h, nullptr); });
  finish(ctx, mem, type);
}

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkDeviceMemory sharedMemory, uint32_t memoryType,
               VkDeviceSize memoryBytes, const std::string& name)
    : size_(size), name_(name) {
  createHandle(ctx);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, handle(), &req);
  if (!(req.memoryTypeBits & (1u << memoryType)) || req.size > memoryBytes)
    throw Error("buffer '" + name_ + "': the shared memory (type " + std::to_string(memoryType) + ", " +
                std::to_string(memoryBytes) + " bytes) does not suit a buffer of " + std::to_string(size_) + " bytes");
  finish(ctx, sharedMemory, memoryType);
}

namespace {
void checkRange(const std::string& name, VkDeviceSize size, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset > size || bytes > size - offset)
    throw Error("buffer '" + name + "': access of " + std::to_string(bytes) + " bytes at offset " +
                std::to_string(offset) + " exceeds its size " + std::to_string(size));
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
