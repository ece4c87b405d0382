#pragma once
// A plain vec4 copy kernel (shaders/copy_vec4.comp): the memory-bandwidth baseline benchmarks measure
// swish's kernels against, on the same device in the same run.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class CopyVec4Pass {
 public:
  static constexpr uint32_t kWorkgroupSize = 64;
  CopyVec4Pass() = default;
  explicit CopyVec4Pass(Context& ctx);
  // Copies `count` vec4 (16 bytes each) from src to dst (16-byte aligned addresses). One dispatch.
  void record(VkCommandBuffer cmd, VkDeviceAddress src, VkDeviceAddress dst, uint32_t count) const;

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
