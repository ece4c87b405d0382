#pragma once
// A compute pipeline built from an embedded SPIR-V module (swish::shaders::find), with
// specialisation constants for the static shapes (constant_id i = specConstants[i], 32-bit each),
// a push-constant range for per-dispatch values, and optionally one descriptor set layout.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Context;

class ComputePipeline {
 public:
  ComputePipeline() = default;
  ComputePipeline(Context& ctx, const std::string& shaderName, const std::vector<uint32_t>& specConstants,
                  uint32_t pushConstantBytes, VkDescriptorSetLayout setLayout = VK_NULL_HANDLE);

  VkPipeline pipeline() const { return pipeline_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }

  // Binds the pipeline, pushes `bytes` of push constants and, when given, binds `set` as set 0.
  void bind(VkCommandBuffer cmd, const void* push, uint32_t bytes, VkDescriptorSet set = VK_NULL_HANDLE) const;

 private:
  VkUnique<VkPipelineLayout> layout_;
  VkUnique<VkPipeline> pipeline_;
};

inline uint32_t groupCount(uint64_t items, uint32_t groupSize) { return uint32_t((items + groupSize - 1) / groupSize); }

}  // namespace swish::gpu
