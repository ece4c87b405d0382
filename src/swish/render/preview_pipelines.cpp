#include "swish/render/preview_pipelines.hpp"

#include <string>
#include <vector>

#include "swish/api_error.hpp"
#include "swish/gpu/embedded_shaders.hpp"
#include "swish/render/host_device.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace swish::render {

namespace {

Owned<VkShaderModule> shaderModule(VkDevice dev, const char* name) {
  const shaders::EmbeddedShader* s = shaders::find(name);
  if (!s)
    throw api::Error(api::ErrorCode::Internal, std::string("preview renderer: shader ") + name + " is not embedded");
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = s->wordCount * 4;
  ci.pCode = s->words;
  VkShaderModule m;
  vkCheck(vkCreateShaderModule(dev, &ci, nullptr, &m), "vkCreateShaderModule");
  return Owned<VkShaderModule>(m, [dev](VkShaderModule h) { vkDestroyShaderModule(dev, h, nullptr); });
}

// One binding per attribute: swish hands each attribute in its own buffer.
Owned<VkPipeline> makePipeline(VkDevice dev, VkPipelineLayout layout, const char* vert, const char* frag,
                               const std::vector<VkFormat>& attributes) {
  const auto vs = shaderModule(dev, vert), fs = shaderModule(dev, frag);
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vs.get();
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fs.get();
  stages[1].pName = "main";
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attrs;
  for (uint32_t i = 0; i < attributes.size(); ++i) {
    const uint32_t size = attributes[i] == VK_FORMAT_R32G32B32A32_SFLOAT ? 16
                          : attributes[i] == VK_FORMAT_R32G32B32_SFLOAT  ? 12
                                                                         : 8;
    bindings.push_back({i, size, VK_VERTEX_INPUT_RATE_VERTEX});
    attrs.push_back({i, i, attributes[i], 0});
  }
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = uint32_t(bindings.size());
  vi.pVertexBindingDescriptions = bindings.data();
  vi.vertexAttributeDescriptionCount = uint32_t(attrs.size());
  vi.pVertexAttributeDescriptions = attrs.data();
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;  // an open garment shows its inside at the collar and sleeves
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;  // no MSAA: silhouettes stay comparable to a CPU rasterisation
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  VkPipelineColorBlendAttachmentState cba{};
  cba.colorWriteMask =
      VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &cba;
  const VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dyn;
  const VkFormat color = PreviewPipelines::kColorFormat;
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = 1;
  ri.pColorAttachmentFormats = &color;
  ri.depthAttachmentFormat = PreviewPipelines::kDepthFormat;
  VkGraphicsPipelineCreateInfo pci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &ri};
  pci.stageCount = 2;
  pci.pStages = stages;
  pci.pVertexInputState = &vi;
  pci.pInputAssemblyState = &ia;
  pci.pViewportState = &vp;
  pci.pRasterizationState = &rs;
  pci.pMultisampleState = &ms;
  pci.pDepthStencilState = &ds;
  pci.pColorBlendState = &cb;
  pci.pDynamicState = &dy;
  pci.layout = layout;
  VkPipeline p;
  vkCheck(vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &pci, nullptr, &p), "vkCreateGraphicsPipelines");
  return Owned<VkPipeline>(p, [dev](VkPipeline h) { vkDestroyPipeline(dev, h, nullptr); });
}

}  // namespace

PreviewPipelines::PreviewPipelines(HostDevice& device) : device_(device.device()) {
  VkDevice dev = device_;
  VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
                                 nullptr};
  VkDescriptorSetLayoutCreateInfo slci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  slci.bindingCount = 1;
  slci.pBindings = &b;
  VkDescriptorSetLayout sl;
  vkCheck(vkCreateDescriptorSetLayout(dev, &slci, nullptr, &sl), "vkCreateDescriptorSetLayout");
  setLayout_ = Owned<VkDescriptorSetLayout>(
      sl, [dev](VkDescriptorSetLayout h) { vkDestroyDescriptorSetLayout(dev, h, nullptr); });

  const VkPushConstantRange pcr{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                sizeof(PreviewPushConstants)};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &sl;
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &pcr;
  VkPipelineLayout pl;
  vkCheck(vkCreatePipelineLayout(dev, &plci, nullptr, &pl), "vkCreatePipelineLayout");
  layout_ = Owned<VkPipelineLayout>(pl, [dev](VkPipelineLayout h) { vkDestroyPipelineLayout(dev, h, nullptr); });

  // Linear filtering where the device can filter swish's normal-map format, nearest otherwise.
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(device.physicalDevice(), VK_FORMAT_R16G16_SNORM, &fp);
  const bool linear = fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sci.magFilter = sci.minFilter = linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sci.maxLod = 0.f;
  VkSampler s;
  vkCheck(vkCreateSampler(dev, &sci, nullptr, &s), "vkCreateSampler");
  sampler_ = Owned<VkSampler>(s, [dev](VkSampler h) { vkDestroySampler(dev, h, nullptr); });

  const VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &ps;
  VkDescriptorPool pool;
  vkCheck(vkCreateDescriptorPool(dev, &dpci, nullptr, &pool), "vkCreateDescriptorPool");
  pool_ = Owned<VkDescriptorPool>(pool, [dev](VkDescriptorPool h) { vkDestroyDescriptorPool(dev, h, nullptr); });
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &sl;
  vkCheck(vkAllocateDescriptorSets(dev, &dsai, &set_), "vkAllocateDescriptorSets");

  jersey_ = makePipeline(
      dev, pl, "preview_jersey.vert", "preview_jersey.frag",
      {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R32G32_SFLOAT});
  body_ = makePipeline(dev, pl, "preview_body.vert", "preview_body.frag",
                       {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT});
}

void PreviewPipelines::bindNormalMaps(VkImageView view, VkImageLayout layout) {
  VkDescriptorImageInfo ii{sampler_.get(), view, layout};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = 0;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  w.pImageInfo = &ii;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

}  // namespace swish::render
