#pragma once
// The tangent-frames pass (shaders/tangent_frames.comp): per-vertex normals and tangents of every
// deformed instance, gathered over the model's precomputed CSR adjacency (core/mesh_frames.hpp), same
// formulas and order as computeVertexFrames, no float atomics.
//
// Records one dispatch (never submits). The caller puts computeToComputeBarrier between the deform
// pass (which writes the positions) and this pass, and a barrier to its consumer after it.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class TangentFramesPass {
 public:
  static constexpr uint32_t kWorkgroupSize = 64;

  struct Args {
    VkDeviceAddress positions = 0;         // float[instances][N][3]
    VkDeviceAddress uvs = 0;               // float[N][2]; unused when !hasUvs
    VkDeviceAddress triangles = 0;         // uint[T][3]
    VkDeviceAddress normalOffsets = 0;     // uint[N+1]
    VkDeviceAddress normalTriangles = 0;   // uint[]
    VkDeviceAddress tangentOffsets = 0;    // uint[N+1]
    VkDeviceAddress tangentTriangles = 0;  // uint[]
    VkDeviceAddress normalsOut = 0;        // float[instances][N][3]
    VkDeviceAddress tangentsOut = 0;       // float[instances][N][4]
    uint32_t vertexCount = 0;
    uint32_t instanceCount = 0;
    bool hasUvs = true;
  };

  TangentFramesPass() = default;
  explicit TangentFramesPass(Context& ctx);
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ComputePipeline pipeline_;
};

}  // namespace swish::gpu
