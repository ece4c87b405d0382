#pragma once
// An empty kernel (shaders/empty.comp): benchmarks record it to measure the fixed cost of a dispatch.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class EmptyDispatchPass {
 public:
  EmptyDispatchPass() = default;
  explicit EmptyDispatchPass(Context& ctx) : pipeline_(ctx, "empty.comp", {}, 0) {}
  // Binds the pipeline and records `dispatches` dispatches of one workgroup of 64 threads.
  void record(VkCommandBuffer cmd, uint32_t dispatches = 1) const {
    pipeline_.bind(cmd, nullptr, 0);
    for (uint32_t i = 0; i < dispatches; ++i) vkCmdDispatch(cmd, 1, 1, 1);
  }

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
