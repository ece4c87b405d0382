#pragma once
// The tangent-frames pass (shaders/tangent_frames.comp): per-vertex normals and tangents of every
// deformed instance, gathered over the model's precomputed CSR adjacency (core/mesh_frames.hpp), same
// formulas and order as computeVertexFrames, no float atomics.
//
// Two ways, same results (bit for bit: same per-triangle values, same sums in the same order):
//  - two passes, with a descriptor set from bindTwoPass (Args::twoPass) and Args::triangleCount:
//    triangle_frames.comp computes each triangle's face and UV terms once per instance into a scratch
//    buffer (triangleTermsBytes(T, instances) bytes), a barrier, then vertex_frames_gather.comp sums
//    them per vertex in one walk of the welded adjacency with the vertex's own triangles marked
//    (frameTriangles). Each triangle's terms are computed once instead of once per adjacent vertex and
//    again for the tangents (~12x fewer). The per-instance streams (positions, terms, the adjacency
//    walked per instance, the frames written) go through the set as texel and storage buffers, the
//    cheap ways on lavapipe (descriptor_binding.hpp); the set's buffers replace the address Args
//    positions, normal/tangent offsets and triangles, normalsOut and tangentsOut;
//  - one pass, without a set (twoPass == VK_NULL_HANDLE): tangent_frames.comp recomputes the terms per
//    vertex, everything behind the address Args.
// Records its dispatches (never submits). The caller puts computeToComputeBarrier between the deform
// pass (which writes the positions) and this pass, and a barrier to its consumer after it.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "swish/core/mesh_frames.hpp"

#include "swish/gpu/compute_pipeline.hpp"
#include "swish/gpu/descriptor_binding.hpp"

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
    // The two-pass path: its descriptor set (bindTwoPass) and the triangle count of `triangles`.
    VkDescriptorSet twoPass = VK_NULL_HANDLE;
    uint32_t triangleCount = 0;
  };

  // The buffers of the two-pass path (each bound from its start; the triangle terms are a scratch of
  // triangleTermsBytes(T, instances) bytes, written then read within the recorded commands, so a frame
  // in flight needs its own).
  struct TwoPassBuffers {
    const Buffer* positions = nullptr;       // float[instances][N][3]
    const Buffer* triangleTerms = nullptr;   // triangleTermsBytes(T, instances) (swish_triangle_frames_layout.h)
    const Buffer* normalOffsets = nullptr;   // uint[N+1], the welded adjacency's
    const Buffer* frameTriangles = nullptr;  // uint[]: frameTriangles(topology)
    const Buffer* normalsOut = nullptr;      // float[instances][N][3]
    const Buffer* tangentsOut = nullptr;     // vec4[instances][N]
  };

  // Bytes of the triangle-terms scratch for `triangles` x `instances`.
  static VkDeviceSize triangleTermsBytes(uint32_t triangles, uint32_t instances);
  static constexpr uint32_t kNotOwnTriangle = 0x80000000u;  // SWISH_NOT_OWN_TRIANGLE
  // The welded (normal) adjacency with kNotOwnTriangle set on the entries that are not in the
  // vertex's own (tangent) adjacency, which must be a subsequence of it (as buildFrameTopology makes
  // them; throws Error otherwise); the offsets are the welded adjacency's.
  static std::vector<uint32_t> frameTriangles(const MeshFrameTopology& topology);

  TangentFramesPass() = default;
  // The two-pass kernels store 64-bit words where the context has shaderInt64 and store64 is true
  // (triangle_frames_store64.comp, vertex_frames_gather_store64.comp; same results).
  explicit TangentFramesPass(Context& ctx, bool store64 = true);
  bool stores64() const { return store64_; }
  DescriptorBinding bindTwoPass(Context& ctx, const TwoPassBuffers& buffers) const;
  // Returns the dispatches recorded: two-pass, 2 (triangle terms, then the per-vertex gather; 1 for a
  // mesh without triangles); single-pass, 1; 0 for an empty input.
  uint32_t record(VkCommandBuffer cmd, const Args& args) const;

 private:
  bool store64_ = false;
  DescriptorLayout twoPassLayout_;
  ComputePipeline pipeline_;          // single pass: tangent_frames.comp
  ComputePipeline trianglePipeline_;  // two passes: triangle_frames.comp ...
  ComputePipeline gatherPipeline_;    // ... then vertex_frames_gather.comp
};

}  // namespace swish::gpu
