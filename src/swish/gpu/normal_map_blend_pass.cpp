#include "swish/gpu/normal_map_blend_pass.hpp"

#include <cstddef>

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/gpu/normal_map_images.hpp"

namespace swish::gpu {

static_assert(sizeof(NormalMapBlendPass::Character) == sizeof(layout::NormalMapBlendCharacter) &&
              offsetof(NormalMapBlendPass::Character, alpha) == offsetof(layout::NormalMapBlendCharacter, alpha));

NormalMapBlendPass::NormalMapBlendPass(Context& ctx)
    : layout_(ctx, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER}),
      pipeline_(ctx, "normal_map_blend.comp", {kWorkgroupSize}, sizeof(layout::NormalMapBlendParams), layout_.get()) {}

DescriptorBinding NormalMapBlendPass::makeBinding(Context& ctx, const NormalMapImages& prev, const NormalMapImages& out,
                                                  const Buffer& decoded) const {
  return DescriptorBinding(ctx, layout_,
                           {BoundResource::storageImage(prev.arrayView()), BoundResource::storageImage(out.arrayView()),
                            BoundResource::texels(decoded, VK_FORMAT_R32G32_UINT)});
}

void NormalMapBlendPass::record(VkCommandBuffer cmd, VkDescriptorSet binding, const Args& a) const {
  if (a.characterCount == 0 || a.width == 0 || a.height == 0) return;
  if (a.width % 4 || a.height % 4)
    throw Error("normal-map blend: map size " + std::to_string(a.width) + "x" + std::to_string(a.height) + " is not a multiple of 4");
  layout::NormalMapBlendParams p;
  p.characters = layout::Address::of(a.characters);
  p.width = a.width;
  p.height = a.height;
  p.characterCount = a.characterCount;
  p.pad0 = 0;
  pipeline_.bind(cmd, &p, sizeof(p), binding);
  vkCmdDispatch(cmd, groupCount(uint64_t(a.width / 4) * (a.height / 4), kWorkgroupSize), 1, a.characterCount);
}

}  // namespace swish::gpu
