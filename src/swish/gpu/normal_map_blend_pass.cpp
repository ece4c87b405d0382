#include "swish/gpu/normal_map_blend_pass.hpp"

#include <cstddef>

#include "shaders/swish_layouts.h"
#include "swish/gpu/context.hpp"
#include "swish/gpu/normal_map_images.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

static_assert(sizeof(NormalMapBlendPass::Character) == sizeof(layout::NormalMapBlendCharacter) &&
              offsetof(NormalMapBlendPass::Character, alpha) == offsetof(layout::NormalMapBlendCharacter, alpha));

NormalMapBlendPass::NormalMapBlendPass(Context& ctx, uint32_t maxBindings) : device_(ctx.device()) {
  const VkDevice dev = device_;
  VkDescriptorSetLayoutBinding b[2]{};
  for (uint32_t i = 0; i < 2; ++i) {
    b[i].binding = i;
    b[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    b[i].descriptorCount = 1;
    b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = 2;
  lci.pBindings = b;
  VkDescriptorSetLayout layout;
  SWISH_VK(vkCreateDescriptorSetLayout(dev, &lci, nullptr, &layout));
  setLayout_ = VkUnique<VkDescriptorSetLayout>(layout, [dev](VkDescriptorSetLayout h) { vkDestroyDescriptorSetLayout(dev, h, nullptr); });

  const uint32_t sets = std::max(1u, maxBindings);
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 2 * sets};
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  pci.maxSets = sets;
  pci.poolSizeCount = 1;
  pci.pPoolSizes = &size;
  VkDescriptorPool pool;
  SWISH_VK(vkCreateDescriptorPool(dev, &pci, nullptr, &pool));
  pool_ = VkUnique<VkDescriptorPool>(pool, [dev](VkDescriptorPool h) { vkDestroyDescriptorPool(dev, h, nullptr); });

  pipeline_ = ComputePipeline(ctx, "normal_map_blend.comp", {kWorkgroupSize, kWorkgroupSize},
                              sizeof(layout::NormalMapBlendParams), layout);
}

VkUnique<VkDescriptorSet> NormalMapBlendPass::makeBinding(const NormalMapImages& prev, const NormalMapImages& out) const {
  VkDescriptorSetLayout layout = setLayout_.get();
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool_.get();
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &layout;
  VkDescriptorSet set;
  const VkResult r = vkAllocateDescriptorSets(device_, &ai, &set);
  if (r == VK_ERROR_OUT_OF_POOL_MEMORY || r == VK_ERROR_FRAGMENTED_POOL)
    throw Error("normal-map blend pass: more descriptor sets requested than the pass was created for");
  if (r != VK_SUCCESS) throwVkError(r, "vkAllocateDescriptorSets", __FILE__, __LINE__);
  VkDescriptorImageInfo images[2] = {{VK_NULL_HANDLE, prev.arrayView(), VK_IMAGE_LAYOUT_GENERAL},
                                     {VK_NULL_HANDLE, out.arrayView(), VK_IMAGE_LAYOUT_GENERAL}};
  VkWriteDescriptorSet w[2]{};
  for (uint32_t i = 0; i < 2; ++i) {
    w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w[i].dstSet = set;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    w[i].pImageInfo = &images[i];
  }
  vkUpdateDescriptorSets(device_, 2, w, 0, nullptr);
  const VkDevice dev = device_;
  const VkDescriptorPool pool = pool_.get();
  return VkUnique<VkDescriptorSet>(set, [dev, pool](VkDescriptorSet h) { vkFreeDescriptorSets(dev, pool, 1, &h); });
}

void NormalMapBlendPass::record(VkCommandBuffer cmd, VkDescriptorSet binding, const Args& a) const {
  if (a.characterCount == 0 || a.width == 0 || a.height == 0) return;
  layout::NormalMapBlendParams p;
  p.decoded = layout::Address::of(a.decoded);
  p.characters = layout::Address::of(a.characters);
  p.width = a.width;
  p.height = a.height;
  p.characterCount = a.characterCount;
  p.pad0 = 0;
  pipeline_.bind(cmd, &p, sizeof(p));
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.layout(), 0, 1, &binding, 0, nullptr);
  vkCmdDispatch(cmd, groupCount(a.width, kWorkgroupSize), groupCount(a.height, kWorkgroupSize), a.characterCount);
}

}  // namespace swish::gpu
