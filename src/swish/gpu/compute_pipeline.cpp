#include "swish/gpu/compute_pipeline.hpp"

#include "swish/gpu/context.hpp"
#include "swish/gpu/embedded_shaders.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

ComputePipeline::ComputePipeline(Context& ctx, const std::string& shaderName, const std::vector<uint32_t>& spec,
                                 uint32_t pushBytes, VkDescriptorSetLayout setLayout) {
  const auto* shader = shaders::find(shaderName);
  if (!shader) throw Error("shader '" + shaderName + "' is not embedded in this build of swish");
  const VkDevice dev = ctx.device();
  if (pushBytes > ctx.properties().limits.maxPushConstantsSize)
    throw Error("shader '" + shaderName + "' needs " + std::to_string(pushBytes) +
                " bytes of push constants, device '" + ctx.deviceName() + "' allows " +
                std::to_string(ctx.properties().limits.maxPushConstantsSize));

  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = shader->wordCount * 4;
  smci.pCode = shader->words;
  VkShaderModule module;
  SWISH_VK(vkCreateShaderModule(dev, &smci, nullptr, &module));
  VkUnique<VkShaderModule> moduleOwner(module, [dev](VkShaderModule h) { vkDestroyShaderModule(dev, h, nullptr); });

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = setLayout ? 1 : 0;
  plci.pSetLayouts = &setLayout;
  plci.pushConstantRangeCount = pushBytes ? 1 : 0;
  plci.pPushConstantRanges = &range;
  VkPipelineLayout layout;
  SWISH_VK(vkCreatePipelineLayout(dev, &plci, nullptr, &layout));
  layout_ = VkUnique<VkPipelineLayout>(layout, [dev](VkPipelineLayout h) { vkDestroyPipelineLayout(dev, h, nullptr); });

  std::vector<VkSpecializationMapEntry> entries;
  for (uint32_t i = 0; i < spec.size(); ++i) entries.push_back({i, i * 4, 4});
  VkSpecializationInfo si{uint32_t(entries.size()), entries.data(), spec.size() * 4, spec.data()};
  VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpci.stage.module = module;
  cpci.stage.pName = "main";
  cpci.stage.pSpecializationInfo = spec.empty() ? nullptr : &si;
  cpci.layout = layout;
  VkPipeline pipeline;
  SWISH_VK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, nullptr, &pipeline));
  pipeline_ = VkUnique<VkPipeline>(pipeline, [dev](VkPipeline h) { vkDestroyPipeline(dev, h, nullptr); });
}

void ComputePipeline::bind(VkCommandBuffer cmd, const void* push, uint32_t bytes, VkDescriptorSet set) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline());
  if (bytes) vkCmdPushConstants(cmd, layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, push);
  if (set != VK_NULL_HANDLE)
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout(), 0, 1, &set, 0, nullptr);
}

}  // namespace swish::gpu
