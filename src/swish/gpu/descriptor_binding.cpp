#include "swish/gpu/descriptor_binding.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

namespace {
VkDeviceSize texelBytes(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
      return 4;
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32_UINT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT:
      return 16;
    default:
      throw Error("descriptor binding: texel format " + std::to_string(int(f)) + " is not one swish binds");
  }
}
}  // namespace

BoundResource BoundResource::texels(const Buffer& b, VkFormat f, VkDeviceSize offset, VkDeviceSize range) {
  BoundResource r;
  r.type = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  r.buffer = &b;
  r.format = f;
  r.offset = offset;
  r.range = range;
  return r;
}

BoundResource BoundResource::storage(const Buffer& b, VkDeviceSize offset, VkDeviceSize range) {
  BoundResource r;
  r.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  r.buffer = &b;
  r.offset = offset;
  r.range = range;
  return r;
}

BoundResource BoundResource::storageImage(VkImageView view) {
  BoundResource r;
  r.type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  r.image = view;
  return r;
}

DescriptorLayout::DescriptorLayout(Context& ctx, std::vector<VkDescriptorType> types) : types_(std::move(types)) {
  std::vector<VkDescriptorSetLayoutBinding> b(types_.size());
  for (uint32_t i = 0; i < b.size(); ++i) {
    b[i].binding = i;
    b[i].descriptorType = types_[i];
    b[i].descriptorCount = 1;
    b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = uint32_t(b.size());
  lci.pBindings = b.data();
  const VkDevice dev = ctx.device();
  VkDescriptorSetLayout layout;
  SWISH_VK(vkCreateDescriptorSetLayout(dev, &lci, nullptr, &layout));
  layout_ = VkUnique<VkDescriptorSetLayout>(
      layout, [dev](VkDescriptorSetLayout h) { vkDestroyDescriptorSetLayout(dev, h, nullptr); });
}

DescriptorBinding::DescriptorBinding(DescriptorBinding&& o) noexcept
    : pool_(std::move(o.pool_)),
      views_(std::move(o.views_)),
      set_(std::exchange(o.set_, VkDescriptorSet(VK_NULL_HANDLE))) {}

DescriptorBinding& DescriptorBinding::operator=(DescriptorBinding&& o) noexcept {
  if (this != &o) {
    set_ = VK_NULL_HANDLE;
    views_.clear();
    pool_ = std::move(o.pool_);
    views_ = std::move(o.views_);
    set_ = std::exchange(o.set_, VkDescriptorSet(VK_NULL_HANDLE));
  }
  return *this;
}

DescriptorBinding::DescriptorBinding(Context& ctx, const DescriptorLayout& layout,
                                     const std::vector<BoundResource>& res) {
  const auto& types = layout.types();
  if (res.size() != types.size())
    throw Error("descriptor binding: " + std::to_string(res.size()) + " resources for " + std::to_string(types.size()) +
                " bindings");
  const VkDevice dev = ctx.device();
  std::map<VkDescriptorType, uint32_t> counts;
  for (VkDescriptorType t : types) ++counts[t];
  std::vector<VkDescriptorPoolSize> sizes;
  for (const auto& [t, n] : counts) sizes.push_back({t, n});
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = 1;
  pci.poolSizeCount = uint32_t(sizes.size());
  pci.pPoolSizes = sizes.data();
  VkDescriptorPool pool;
  SWISH_VK(vkCreateDescriptorPool(dev, &pci, nullptr, &pool));
  pool_ = VkUnique<VkDescriptorPool>(pool, [dev](VkDescriptorPool h) { vkDestroyDescriptorPool(dev, h, nullptr); });
  VkDescriptorSetLayout setLayout = layout.get();
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &setLayout;
  SWISH_VK(vkAllocateDescriptorSets(dev, &ai, &set_));

  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  std::vector<VkBufferView> viewOf(res.size(), VK_NULL_HANDLE);
  std::vector<VkDescriptorBufferInfo> bufferOf(res.size());
  std::vector<VkDescriptorImageInfo> imageOf(res.size());
  std::vector<VkWriteDescriptorSet> writes(res.size());
  for (uint32_t i = 0; i < res.size(); ++i) {
    const BoundResource& r = res[i];
    const std::string where = "descriptor binding " + std::to_string(i);
    if (r.type != types[i]) throw Error(where + ": the resource's type does not match the layout");
    VkWriteDescriptorSet& w = writes[i];
    w = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set_;
    w.dstBinding = i;
    w.descriptorCount = 1;
    w.descriptorType = r.type;
    if (r.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE) {
      if (!r.image) throw Error(where + ": no image view");
      imageOf[i] = {VK_NULL_HANDLE, r.image, VK_IMAGE_LAYOUT_GENERAL};
      w.pImageInfo = &imageOf[i];
      continue;
    }
    if (!r.buffer) throw Error(where + ": no buffer");
    const Buffer& b = *r.buffer;
    if (r.offset >= b.size()) throw Error(where + ": offset beyond buffer '" + b.name() + "'");
    const VkDeviceSize rest = b.size() - r.offset;
    const VkDeviceSize bytes = r.range == VK_WHOLE_SIZE ? rest : std::min(r.range, rest);
    if (r.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) {
      if (r.offset % limits.minStorageBufferOffsetAlignment)
        throw Error(where + ": storage offset into '" + b.name() + "' is not aligned to the device's minimum");
      bufferOf[i] = {b.handle(), r.offset, bytes};
      w.pBufferInfo = &bufferOf[i];
      continue;
    }
    const VkDeviceSize texel = texelBytes(r.format);
    if (r.offset % limits.minTexelBufferOffsetAlignment)
      throw Error(where + ": texel offset into '" + b.name() + "' is not aligned to the device's minimum");
    const VkDeviceSize texels = bytes / texel;
    if (texels == 0) throw Error(where + ": buffer '" + b.name() + "' holds no whole texel");
    if (texels > limits.maxTexelBufferElements)
      throw Error(where + ": buffer '" + b.name() + "' holds " + std::to_string(texels) +
                  " texels, beyond the device's " + std::to_string(limits.maxTexelBufferElements) +
                  " (maxTexelBufferElements); use fewer instances per batch");
    VkBufferViewCreateInfo vci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    vci.buffer = b.handle();
    vci.format = r.format;
    vci.offset = r.offset;
    vci.range = texels * texel;
    VkBufferView view;
    SWISH_VK(vkCreateBufferView(dev, &vci, nullptr, &view));
    views_.emplace_back(view, [dev](VkBufferView h) { vkDestroyBufferView(dev, h, nullptr); });
    viewOf[i] = view;
    w.pTexelBufferView = &viewOf[i];
  }
  vkUpdateDescriptorSets(dev, uint32_t(writes.size()), writes.data(), 0, nullptr);
}

}  // namespace swish::gpu
