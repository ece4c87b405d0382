#pragma once
// The normal-map blend pass (shaders/normal_map_blend.comp): the temporal filter's blend of each
// character's newly selected, decoded map into its normal map, out = mix(prev, decoded, alpha), for all
// characters in one dispatch, one invocation per 4-texel column of 16, 8 or 4 rows of a character (the
// most the map height allows), into the characters' RG16_SNORM image array (NormalMapImages), which
// renderers sample: written directly where the images share the out buffer's memory
// (NormalMapImages::sharesTexels: linear images laid out as the packed texels), else by one copy of
// the out buffer into the image layers.
//
// The blend works on buffers of packed texels (uint32[layer][height][width], snorm16 X | Y << 16: the
// memory layout of R16G16_SNORM), not on the images: prev is the previous frame's buffer, out this
// frame's. On lavapipe a storage-image load or store of RG16_SNORM converts the format lane by lane;
// the buffer form reads and writes 4 texels per texel fetch or store, and the copy into the images is
// a memcpy (22 characters of 256x256: see normal_map_blend.comp for the figures). With shared texels
// there is no copy at all: bench_replay's BM_ReplayRatio, lavapipe on 2 cores, 6 runs alternating with
// the copy (a scratch switch): 22 characters against 1, blend stage 12.7x -> 10.3x, whole frame
// (wall) 6.25x -> 5.66x (medians; lower in each of the 6 pairs).
//
// prev, out and the decoded slots (VqDecodePass output) are bound through a descriptor set made by
// makeBinding(); prev and out may be the same buffer (one frame in flight). Records one dispatch and,
// unless the images share out's memory, one copy (never submits). The caller places computeToComputeBarrier after the
// VQ decode pass and before this one (which also orders this frame's read of `prev` after the previous frame's write of
// it on the same queue). The images are written by a transfer, after which record() places a barrier
// TRANSFER/TRANSFER_WRITE -> COMPUTE_SHADER/SHADER_READ|WRITE, so that the documented contract for a
// renderer holds unchanged: a barrier COMPUTE_SHADER/SHADER_WRITE -> its own stage/SHADER_READ
// before sampling `out` (the two form a dependency chain). With shared texels the dispatch writes the
// images' memory through the buffer, and record() places a global memory barrier COMPUTE_SHADER/
// SHADER_WRITE -> COMPUTE_SHADER/SHADER_READ|WRITE after it: it makes those writes available (a
// renderer's image barrier alone covers only accesses through the image), and the renderer's barrier
// from the compute stage chains to it as above.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>

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

  // Workgroups: a divisor of the block columns (width / 4) between kMinRowGroup and kMaxRowGroup (the
  // largest there is), so that the dispatch covers each map exactly; else kFallbackGroup with a bounds
  // check in the shader.
  static constexpr uint32_t kMinRowGroup = 16, kMaxRowGroup = 256, kFallbackGroup = 64;
  // Texel rows per invocation (the shader's ROWS): the first of these dividing the map height, which
  // record() checks is a multiple of 4 (normal_map_blend.glsl says why); one pipeline each, made by the
  // constructor.
  static constexpr uint32_t kRowsPerInvocation[3] = {16, 8, 4};

  // Bytes of `layers` maps of packed texels (the prev and out buffers).
  static VkDeviceSize texelBytes(uint32_t width, uint32_t height, uint32_t layers) {
    return VkDeviceSize(width) * height * layers * 4;
  }

  struct Args {
    VkDeviceAddress characters = 0;  // Character[characterCount]
    uint32_t width = 0, height = 0;  // multiples of 4, those of the bound buffers, decoded slots and images; width
                                     // that of the pass
    uint32_t characterCount = 0;     // <= layers of the bound buffers and of outMaps
    // uint[characterCount]: the layer each character blends (of prev, out and outMaps), distinct; 0:
    // character c blends layer c. hostLayers: the same list on the host (for the copy into outMaps;
    // required with `layers`, each below maxLayers, else Error).
    VkDeviceAddress layers = 0;
    std::span<const uint32_t> hostLayers;
    uint32_t maxLayers = 0;               // layers of the bound buffers and images (checked against hostLayers)
    VkBuffer outTexels = VK_NULL_HANDLE;  // the `out` buffer of the binding, copied into outMaps
    VkImage outMaps = VK_NULL_HANDLE;     // a NormalMapImages::image() (layout GENERAL): the characters' layers written
    bool outMapsShareTexels = false;  // outMaps lies over outTexels' memory (NormalMapImages::sharesTexels): no copy
  };

  NormalMapBlendPass() = default;
  // For maps `width` texels wide (a multiple of 4; the dispatch shape depends on it). The shader stores
  // 64-bit words where the context has shaderInt64 and store64 is true (normal_map_blend.glsl).
  NormalMapBlendPass(Context& ctx, uint32_t width, bool store64 = true);
  uint32_t width() const { return width_; }
  uint32_t rowGroup() const { return rowGroup_; }  // block columns per workgroup
  bool exact() const { return exact_; }            // rowGroup() divides width / 4
  bool stores64() const { return store64_; }       // normal_map_blend_store64.comp

  // A descriptor set binding the packed texels `prev` (read), `out` (written) and the decoded slots
  // `decoded` (uint16[slots][height][width], from its start).
  DescriptorBinding makeBinding(Context& ctx, const Buffer& prev, const Buffer& out, const Buffer& decoded) const;
  // Returns the dispatches recorded (1, and the copy; 0 for an empty input).
  uint32_t record(VkCommandBuffer cmd, VkDescriptorSet binding, const Args& args) const;

 private:
  uint32_t width_ = 0, rowGroup_ = 0;
  bool exact_ = false, store64_ = false;
  DescriptorLayout layout_;
  ComputePipeline pipelines_[3];  // one per kRowsPerInvocation
};

}  // namespace swish::gpu
