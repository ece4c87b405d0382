#pragma once
// The tangent-frames pass (shaders/tangent_frames.comp): per-vertex normals and tangents of every
// deformed instance, gathered over the model's precomputed CSR adjacency (core/mesh_frames.hpp), same
// formulas and order as computeVertexFrames, no float atomics.
//
// Two ways, same results (bit for bit: same per-triangle values, same sums in the same order):
//  - with a triangle-terms scratch buffer (Args::triangleTerms, triangleTermsBytes(T, instances) bytes)
//    and Args::triangleCount: triangle_frames.comp computes each triangle's face and UV terms once per
//    instance, a barrier, then vertex_frames_gather.comp sums them per vertex. Each triangle's terms
//    are computed once instead of once per adjacent vertex and again for the tangents (~12x fewer);
//  - without (triangleTerms == 0): the single-pass tangent_frames.comp recomputes them per vertex.
// Records its dispatches (never submits). The caller puts computeToComputeBarrier between the deform
// pass (which writes the positions) and this pass, and a barrier to its consumer after it.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "swish/gpu/compute_pipeline.hpp"

namespace swish::gpu {

class TangentFramesPass {
 public:
  static constexpr uint32_t kWorkgroupSize = 256;

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
    // Optional scratch for the two-pass path: vec4[instances][triangleCount][3], written then read
    // within the recorded commands (a frame in flight needs its own).
    VkDeviceAddress triangleTerms = 0;
    uint32_t triangleCount = 0;  // triangles of `triangles`; needed with triangleTerms
  };

  // Bytes of the triangle-terms scratch for `triangles` x `instances`.
  static VkDeviceSize triangleTermsBytes(uint32_t triangles, uint32_t instances);

  TangentFramesPass() = default;
  explicit TangentFramesPass(Context& ctx);
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ComputePipeline pipeline_;         // single pass: tangent_frames.comp
  ComputePipeline trianglePipeline_; // two passes: triangle_frames.comp ...
  ComputePipeline gatherPipeline_;   // ... then vertex_frames_gather.comp
};

}  // namespace swish::gpu
