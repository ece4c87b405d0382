#pragma once
// The VQ decode pass (shaders/vq_decode.comp): decodes database maps, each ONCE into its own slot of a
// buffer (uint16 per texel: low byte X, high byte Y, snorm8), however many characters chose it; a job
// list says which map goes into which slot, so that a caller keeping decoded maps across frames
// (FrameRecorder does: database maps are constant) decodes only the maps newly selected. Lossless: the
// output equals runtime/reference_vq_decode exactly.
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
    VkDeviceAddress jobMaps = 0;     // uint[jobCount]: database map decoded by each job
    VkDeviceAddress jobSlots = 0;    // uint[jobCount]: slot each job writes; 0: job j writes slot j
    VkDeviceAddress decodedOut = 0;  // uint16[slots][height][width]
    uint32_t width = 0, height = 0;  // multiples of 4
    uint32_t jobCount = 0;
    uint32_t codebookSize = 0;
  };

  VqDecodePass() = default;
  explicit VqDecodePass(Context& ctx);
  // Returns the dispatches recorded (1; 0 when there is no job).
  uint32_t record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
