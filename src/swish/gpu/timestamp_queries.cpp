#include "swish/gpu/timestamp_queries.hpp"

#include <algorithm>
#include <limits>

#include "swish/gpu/context.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

TimestampQueries::TimestampQueries(Context& ctx, uint32_t capacity) : capacity_(capacity), written_(capacity, false) {
  device_ = ctx.device();
  if (!ctx.supportsTimestamps() || capacity == 0) return;
  periodNs_ = ctx.timestampPeriodNs();
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &n, fams.data());
  const uint32_t bits = fams[ctx.queueFamily()].timestampValidBits;
  validMask_ = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = capacity;
  VkQueryPool pool;
  SWISH_VK(vkCreateQueryPool(device_, &qci, nullptr, &pool));
  const VkDevice dev = device_;
  pool_ = VkUnique<VkQueryPool>(pool, [dev](VkQueryPool h) { vkDestroyQueryPool(dev, h, nullptr); });
}

void TimestampQueries::reset(VkCommandBuffer cmd) {
  std::fill(written_.begin(), written_.end(), false);
  if (pool_) vkCmdResetQueryPool(cmd, pool_.get(), 0, capacity_);
}

void TimestampQueries::mark(VkCommandBuffer cmd, uint32_t index) {
  if (index >= capacity_)
    throw Error("timestamp index " + std::to_string(index) + " beyond the pool's " + std::to_string(capacity_));
  written_[index] = true;
  if (pool_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), index);
}

std::vector<double> TimestampQueries::readNs() const {
  std::vector<double> out(capacity_, std::numeric_limits<double>::quiet_NaN());
  if (!pool_) return out;
  std::vector<uint64_t> raw(capacity_ * 2, 0);
  // Per-query availability, so marks never written this time are reported as NaN instead of waiting.
  vkGetQueryPoolResults(device_, pool_.get(), 0, capacity_, raw.size() * sizeof(uint64_t), raw.data(),
                        2 * sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
  if (!written_[0] || raw[1] == 0) return out;
  const uint64_t t0 = raw[0] & validMask_;
  for (uint32_t i = 0; i < capacity_; ++i)
    if (written_[i] && raw[2 * i + 1] != 0) out[i] = double(((raw[2 * i] & validMask_) - t0) & validMask_) * periodNs_;
  return out;
}

}  // namespace swish::gpu
