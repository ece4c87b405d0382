#pragma once
// A storage buffer with its own memory, addressable from shaders (buffer device address). swish needs
// a few big buffers per model and per instance batch, so one allocation per buffer is enough (no VMA).
//   HostVisible: mapped for its lifetime (per-frame inputs, readback, tests).
//   DeviceLocal: filled through a staging copy (model data); host-visible when the device has such memory.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Context;

enum class MemoryKind { HostVisible, DeviceLocal };

class Buffer {
 public:
  Buffer() = default;
  // size 0 is rounded up to 4 bytes so every buffer has an address. `name` appears in errors.
  Buffer(Context& ctx, VkDeviceSize size, MemoryKind kind, const std::string& name);
  // A buffer over memory another object allocated and owns (at offset 0; mapped when host visible),
  // which must outlive it: NormalMapImages shares its image's memory this way. The memory must have
  // been allocated with VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT, of a type in requirements(ctx, size),
  // and at least requirements(ctx, size).size bytes (checked).
  Buffer(Context& ctx, VkDeviceSize size, VkDeviceMemory sharedMemory, uint32_t memoryType, VkDeviceSize memoryBytes,
         const std::string& name);
  // The memory requirements of a Buffer of `size` bytes (its usage flags), without creating one.
  static VkMemoryRequirements requirements(Context& ctx, VkDeviceSize size);

  VkBuffer handle() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  VkDeviceAddress address() const { return address_; }
  bool mapped() const { return mapped_ != nullptr; }
  void* data() const { return mapped_; }  // nullptr unless host visible
  const std::string& name() const { return name_; }

  // Writes bytes at `offset`: memcpy when mapped, else a staging copy submitted and waited on.
  void upload(Context& ctx, const void* src, VkDeviceSize bytes, VkDeviceSize offset = 0);
  template <class T>
  void upload(Context& ctx, std::span<const T> src, VkDeviceSize offset = 0) {
    upload(ctx, src.data(), src.size_bytes(), offset);
  }
  // Reads bytes back (waits through a staging copy when not mapped).
  void download(Context& ctx, void* dst, VkDeviceSize bytes, VkDeviceSize offset = 0) const;

 private:
  void createHandle(Context& ctx);
  void finish(Context& ctx, VkDeviceMemory memory,
              uint32_t memoryType);  // binds, maps when host visible, gets the address
  VkUnique<VkBuffer> buffer_;
  VkUnique<VkDeviceMemory> memory_;  // empty for a buffer over shared memory
  VkDeviceSize size_ = 0;
  VkDeviceAddress address_ = 0;
  void* mapped_ = nullptr;
  VkDevice device_ = VK_NULL_HANDLE;
  std::string name_;
};

// The barrier between two compute dispatches where the second reads what the first wrote through
// buffers or storage images (a global memory barrier: shader write -> shader read).
void computeToComputeBarrier(VkCommandBuffer cmd);
// After the last dispatch whose results the host reads through mapped memory (after the fence).
void computeToHostBarrier(VkCommandBuffer cmd);

}  // namespace swish::gpu
