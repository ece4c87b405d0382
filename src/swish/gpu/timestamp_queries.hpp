#pragma once
// GPU timestamps around passes: a query pool of `capacity` timestamps. record(cmd) resets it (once per
// use of a command buffer, before the first mark); mark(cmd, i) writes timestamp i after all earlier
// work completes; after the submission's fence, readNs() gives each mark in nanoseconds relative
// to mark 0 (NaN for marks never written). On devices without timestamps every call is a no-op and
// readNs() returns NaNs.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Context;

class TimestampQueries {
 public:
  TimestampQueries() = default;
  TimestampQueries(Context& ctx, uint32_t capacity);

  void reset(VkCommandBuffer cmd);
  void mark(VkCommandBuffer cmd, uint32_t index);
  std::vector<double> readNs() const;

 private:
  VkUnique<VkQueryPool> pool_;
  VkDevice device_ = VK_NULL_HANDLE;
  uint32_t capacity_ = 0;
  double periodNs_ = 1.0;
  uint64_t validMask_ = ~0ull;
  std::vector<bool> written_;
};

}  // namespace swish::gpu
