#pragma once
// The normal-map blend pass (shaders/normal_map_blend.comp): the temporal filter's blend of each
// character's newly selected, decoded map into its normal map, out = mix(prev, decoded, alpha), for all
// characters in one dispatch (one layer of a NormalMapImages array per character), one invocation per
// 4x4 block of a character.
//
// prev, out and the decoded slots (VqDecodePass output, read as texels) are bound through a descriptor
// set made by makeBinding(); prev and out may be the same images (one frame in flight). Records one
// dispatch (never submits). The caller places computeToComputeBarrier after the VQ decode pass and
// before this one (which also orders this frame's read of `prev` after the previous frame's write of it
// on the same queue), and a barrier COMPUTE_SHADER/SHADER_WRITE -> its own stage/SHADER_READ before
// sampling `out`.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"
#include "swish/gpu/descriptor_binding.hpp"

namespace swish::gpu {

class NormalMapImages;

class NormalMapBlendPass {
 public:
  // One character's entry of the `characters` buffer (layout::NormalMapBlendCharacter in
  // shaders/swish_layouts.h; the .cpp asserts they match).
  struct Character {
    uint32_t decodedSlot;  // slot of the decoded map this character selected
    float alpha;           // weight of the new map
  };

  static constexpr uint32_t kWorkgroupSize = 64;  // 4x4 blocks

  struct Args {
    VkDeviceAddress characters = 0;  // Character[characterCount]
    uint32_t width = 0, height = 0;  // multiples of 4, those of the bound images and decoded slots
    uint32_t characterCount = 0;     // <= layers of the bound images
  };

  NormalMapBlendPass() = default;
  explicit NormalMapBlendPass(Context& ctx);

  // A descriptor set binding `prev` (read), `out` (written) and the decoded slots `decoded`
  // (uint16[slots][height][width], from its start).
  DescriptorBinding makeBinding(Context& ctx, const NormalMapImages& prev, const NormalMapImages& out, const Buffer& decoded) const;
  void record(VkCommandBuffer cmd, VkDescriptorSet binding, const Args& args) const;

 private:
  DescriptorLayout layout_;
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
