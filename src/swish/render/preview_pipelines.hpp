#pragma once
// The preview's graphics pipelines (dynamic rendering, no render pass objects): the jersey, fed by
// swish's four vertex streams and sampling swish's normal-map array, and the mannequin body. Shaders:
// shaders/preview_{jersey,body}.{vert,frag}, embedded at build time.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/render/vk_owned.hpp"

namespace swish::render {

class HostDevice;

// Mirrors PreviewPush in shaders/preview_common.glsl.
struct PreviewPushConstants {
  float viewProj[16];
  float cameraPos[4];
  float lightDir[4];
  float baseColor[4];
  uint32_t layer;
  uint32_t useNormalMap;
};
static_assert(sizeof(PreviewPushConstants) == 120, "must match shaders/preview_common.glsl");

class PreviewPipelines {
 public:
  static constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
  static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

  explicit PreviewPipelines(HostDevice& device);

  VkPipeline jersey() const { return jersey_.get(); }
  VkPipeline body() const { return body_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }
  VkDescriptorSet descriptorSet() const { return set_; }
  // Points the jersey's sampler at a normal-map array view (in `layout`). Only while no submitted
  // command buffer that binds the set is pending.
  void bindNormalMaps(VkImageView view, VkImageLayout layout);

 private:
  VkDevice device_;
  Owned<VkDescriptorSetLayout> setLayout_;
  Owned<VkPipelineLayout> layout_;
  Owned<VkSampler> sampler_;
  Owned<VkDescriptorPool> pool_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  Owned<VkPipeline> jersey_, body_;
};

}  // namespace swish::render
