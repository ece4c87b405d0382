#pragma once
// The deform pass (shaders/deform.comp): PCA reconstruction + linear blend skinning of every instance
// of one model in ONE dispatch; each vertex's basis values are read once per frame for all instances.
//
// Records one dispatch into the caller's command buffer (never submits). Synchronisation the caller
// provides: inputs written by the host before the submission (mapped memory; the submission makes them
// visible) or by earlier GPU work followed by a barrier to COMPUTE_SHADER/SHADER_READ; after it, a
// barrier COMPUTE_SHADER/SHADER_WRITE -> the consumer's stage and access (computeToComputeBarrier for
// the tangent-frames pass, VERTEX_INPUT/VERTEX_ATTRIBUTE_READ for a renderer).
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class DeformPass {
 public:
  static constexpr uint32_t kWorkgroupSize = 256;

  struct Args {
    VkDeviceAddress mean = 0;          // float[3N]
    VkDeviceAddress basis = 0;         // float[K][3N]
    VkDeviceAddress weights = 0;       // float[instances][K]
    VkDeviceAddress skinMatrices = 0;  // mat4[instances][jointCount], column-major
    VkDeviceAddress skinJoints = 0;    // uint[N][influences]
    VkDeviceAddress skinWeights = 0;   // float[N][influences]
    VkDeviceAddress positionsOut = 0;  // float[instances][N][3]
    uint32_t vertexCount = 0;
    uint32_t instanceCount = 0;
    uint32_t jointCount = 0;
  };

  DeformPass() = default;
  // meshComponents (K) in 1..SWISH_MAX_MESH_COMPONENTS; influences in 1..8. applySkinning = false writes
  // the pre-skinning shape (used to check the PCA reconstruction on its own).
  DeformPass(Context& ctx, uint32_t meshComponents, uint32_t influences, bool applySkinning = true);

  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
