#pragma once
// The VQ decode pass (shaders/vq_decode.comp): decodes the database maps selected this frame, each
// ONCE into its own slot of a scratch buffer (uint16 per texel: low byte X, high byte Y, snorm8),
// however many characters chose it. Lossless: the output equals runtime/reference_vq_decode exactly.
//
// Records one dispatch (never submits). The caller places computeToComputeBarrier between it and the
// normal-map blend pass that reads the slots.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class VqDecodePass {
 public:
  static constexpr uint32_t kWorkgroupSize = 64;

  struct Args {
    VkDeviceAddress codebook = 0;    // int8[entries][16][2], padded to whole words
    VkDeviceAddress indices = 0;     // uint16[maps][blocks], padded to whole words
    VkDeviceAddress slotMaps = 0;    // uint[slotCount]: database map of each slot
    VkDeviceAddress decodedOut = 0;  // uint16[slotCount][height][width]
    uint32_t width = 0, height = 0;  // multiples of 4
    uint32_t slotCount = 0;
    uint32_t codebookSize = 0;
  };

  VqDecodePass() = default;
  explicit VqDecodePass(Context& ctx);
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
