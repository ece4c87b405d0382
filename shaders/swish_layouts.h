// Buffer layouts and push-constant blocks shared by the GLSL compute shaders and the C++ passes
// (src/swish/gpu/*). Included by both: GLSL sees SWISH_ADDRESS as uvec2 (GL_EXT_buffer_reference_uvec2,
// so no shaderInt64 is needed), C++ sees an 8-byte aligned pair of words holding a VkDeviceAddress.
// Every struct is laid out with std430 / push-constant rules; C++ checks the sizes with static_asserts.
//
// Data layouts (all tightly packed 32-bit words unless said otherwise):
//   positions/normals : float[instance][vertex][3]   (same as swish::Points3f rows, one block per instance)
//   tangents          : float[instance][vertex][4]   (xyz tangent, w = bitangent sign)
//   PCA mean          : float[3N];  PCA basis: float[k][3N] (column-major 3N x K, as Eigen stores MeshPca::basis)
//   mesh weights      : float[instance][K4], K4 = K rounded up to 4, zero padded (read as vec4 texels);
//                       an instance at a quality level of k < K components has zeros from k on
//   instance order    : uint[instance], the instances band by band (deform quality levels, deform.glsl)
//   skin matrix rows  : vec4[instance][joint][3], rows 0..2 of each affine skinning matrix (texels)
//   skin joints       : uint[vertex][influences];  skin weights: float[vertex][influences]
//   body anchors      : uvec4 texels (words, 4 a texel). First, per vertex, its push-out joint table's
//                       extra joints: uint[vertex][XT * 4] (XT = ceil(E / 4), E extra joints, unused ones
//                       0). The table is the vertex's skin joints (slots 0..influences-1), then those E.
//                       Then per anchor set: [set][vertex][ST] texels, ST = 1 + ceil(T / 4) (T = influences
//                       + E table slots): float ball centre xyz (rest), float reach (radius + clearance;
//                       0: no anchor), then float weights[T] over the table's slots (zero padded).
//                       DeformPass::packAnchors writes it.
//   triangles         : uint[triangle][3];  adjacency: CSR offsets uint[N+1], triangles uint[]
//   VQ codebook       : int8[entry][16 texels][2] read as uint words (2 texels per word)
//   VQ indices        : uint16[map][block] read as uint words (2 indices per word, little-endian)
//   decoded maps      : uint16[slot][height][width] read as uint words: per texel low byte = X, high byte = Y
//                       (snorm8, exactly the codebook bytes: decoding is a lossless gather)
#ifndef SWISH_LAYOUTS_H
#define SWISH_LAYOUTS_H

#ifdef __cplusplus
#include <cstdint>
namespace swish::gpu::layout {
using uint = uint32_t;
struct alignas(8) Address {
  uint32_t lo = 0, hi = 0;
  static Address of(uint64_t a) { return {uint32_t(a), uint32_t(a >> 32)}; }
};
#define SWISH_ADDRESS Address
#else
#define SWISH_ADDRESS uvec2
#endif

// Largest K the deform kernel accepts (its per-thread basis registers are sized by K; beyond a few
// hundred they would spill).
#define SWISH_MAX_MESH_COMPONENTS 256

// The most anchor sets in the body-anchor buffer (layout above), and the most extra joints a vertex's
// push-out table may need: every influence of every set off the vertex's skin joints (3 sets x 4).
#define SWISH_MAX_ANCHOR_SLOTS 3
#define SWISH_MAX_ANCHOR_EXTRA_JOINTS 12

// deform.comp: PCA reconstruction + linear blend skinning of `instanceCount` instances, then the
// push-out of the body anchors' balls (runtime/reference_push_out.hpp). The mesh weights
// (float[instanceCount][K4]) and skin matrix rows (vec4[instanceCount][jointCount][3]) are texel
// buffers of its descriptor set. Quality levels (pipelines with more than one band): the instances
// come band by band in instanceOrder, band b ending at bandEnd[b] (the last at instanceCount), each
// reading its band's weight groups; every vertex loads only the first maxGroups groups of its basis.
struct DeformParams {
  SWISH_ADDRESS mean;            // float[3N]
  SWISH_ADDRESS basis;           // float[K][3N]
  SWISH_ADDRESS skinJoints;      // uint[N][influences]
  SWISH_ADDRESS skinWeights;     // float[N][influences]
  SWISH_ADDRESS positionsOut;    // float[instanceCount][N][3]
  SWISH_ADDRESS anchors;         // body anchors, the layout above (unused when pushOut is 0)
  SWISH_ADDRESS instanceOrder;   // uint[instanceCount]: instances by band (unused with one band)
  uint vertexCount;
  uint instanceCount;
  uint jointCount;
  uint pushOut;                  // anchor sets to push out of (0: no push-out; at most SWISH_MAX_ANCHOR_SLOTS)
  uint maxGroups;                // basis groups each vertex loads: the widest band in use (K4 / 4 at most)
  uint bandEnd[4];               // end of bands 0..3 in instanceOrder (bands beyond the pipeline's: unused)
  uint pad0;
};

// tangent_frames.comp: normals and tangents of deformed meshes, one thread per (vertex, instance).
struct TangentFramesParams {
  SWISH_ADDRESS positions;         // float[instanceCount][N][3]
  SWISH_ADDRESS uvs;               // float[N][2] (ignored when hasUvs == 0)
  SWISH_ADDRESS triangles;         // uint[T][3]
  SWISH_ADDRESS normalOffsets;     // uint[N+1]  (welded adjacency)
  SWISH_ADDRESS normalTriangles;   // uint[]
  SWISH_ADDRESS tangentOffsets;    // uint[N+1]  (own triangles)
  SWISH_ADDRESS tangentTriangles;  // uint[]
  SWISH_ADDRESS normalsOut;        // float[instanceCount][N][3]
  SWISH_ADDRESS tangentsOut;       // float[instanceCount][N][4]
  uint vertexCount;
  uint instanceCount;
  uint hasUvs;
  uint pad0;
};

// vq_decode.comp: decodes database maps into decoded slots, one thread per texel pair; job j decodes
// map jobMaps[j] into slot jobSlots[j] (slot j when jobSlots is 0).
struct VqDecodeParams {
  SWISH_ADDRESS codebook;     // uint words of int8[entry][16][2]
  SWISH_ADDRESS indices;      // uint words of uint16[map][block]
  SWISH_ADDRESS jobMaps;      // uint[jobCount]: database map decoded by each job
  SWISH_ADDRESS jobSlots;     // uint[jobCount]: slot written by each job (0: job j writes slot j)
  SWISH_ADDRESS decodedOut;   // uint words of uint16[slot][height][width]
  uint width;
  uint height;
  uint jobCount;
  uint codebookSize;          // entries; larger indices decode to 0 (the CPU reference does the same)
};

// One character of normal_map_blend.comp.
struct NormalMapBlendCharacter {
  uint decodedSlot;   // slot of the decoded map this character selected this frame
  float alpha;        // weight of the new map: out = mix(prev, decoded, alpha)
};

// normal_map_blend.comp: temporal blend into the per-character layers of an RG16_SNORM 2D array image.
// The decoded slots are a texel buffer (R32G32_UINT: 4 texels of a block row per texel) of its
// descriptor set, beside the previous and current images.
struct NormalMapBlendParams {
  SWISH_ADDRESS characters;   // NormalMapBlendCharacter[characterCount]
  SWISH_ADDRESS layers;       // uint[characterCount]: the layer (of prev and out) of each character; 0: c -> c
  uint width;
  uint height;
  uint characterCount;
  uint pad0;
};

// copy_vec4.comp (benchmark baseline): out[i] = in[i] for vec4 i < count.
struct CopyVec4Params {
  SWISH_ADDRESS src;
  SWISH_ADDRESS dst;
  uint count;
  uint pad0;
};

#ifdef __cplusplus
static_assert(sizeof(Address) == 8);
static_assert(sizeof(DeformParams) == 7 * 8 + 40);
static_assert(sizeof(TangentFramesParams) == 9 * 8 + 16);
static_assert(sizeof(VqDecodeParams) == 5 * 8 + 16);
static_assert(sizeof(NormalMapBlendCharacter) == 8);
static_assert(sizeof(NormalMapBlendParams) == 2 * 8 + 16);
static_assert(sizeof(CopyVec4Params) == 2 * 8 + 8);
static_assert(sizeof(TangentFramesParams) <= 128 && sizeof(DeformParams) <= 128,
              "push constants: 128 bytes are all Vulkan guarantees");
}  // namespace swish::gpu::layout
#undef SWISH_ADDRESS
#endif

#endif  // SWISH_LAYOUTS_H
