// Push-constant blocks and descriptor bindings of the two-pass tangent frames (triangle_frames.comp,
// then vertex_frames_gather.comp), shared by GLSL and C++ like swish_layouts.h (which it includes for
// the address type): GLSL sees the addresses as uvec2, C++ as swish::gpu::layout::Address.
//
// Both kernels use one descriptor set layout (TangentFramesPass::bindTwoPass); the per-instance
// streams are in it, model data read once per triangle stays behind addresses:
// Triangle terms (written by the triangle pass, read by the gather): vec4[instance][triangle][3]
//   [0] = cross(e1, e2) of the triangle's edges from corner 0 (the face normal term, xyz; w = 0)
//   [1] = the UV tangent term (e1 * d2.y - e2 * d1.y) / r (xyz), w = 1 if the triangle has a usable UV
//         parameterisation (r != 0 and finite), w = 0 if core/mesh_frames.cpp skips it
//   [2] = the UV bitangent term (e2 * d1.x - e1 * d2.x) / r (xyz; w = 0)
// [1] and [2] are written only when the mesh has UVs.
#ifndef SWISH_TRIANGLE_FRAMES_LAYOUT_H
#define SWISH_TRIANGLE_FRAMES_LAYOUT_H

#include "swish_layouts.h"

#ifdef __cplusplus
namespace swish::gpu::layout {
#define SWISH_TF_ADDRESS Address
#else
#define SWISH_TF_ADDRESS uvec2
#endif

#define SWISH_TRIANGLE_TERM_VEC4S 3

#define SWISH_TF_BINDING_POSITIONS 0          // uniform texel buffer R32_SFLOAT: float[instance][N][3]
#define SWISH_TF_BINDING_TERMS_OUT 1          // storage buffer: vec4[instance][T][3] (triangle pass writes)
#define SWISH_TF_BINDING_TERMS 2              // uniform texel buffer R32G32B32A32_SFLOAT: the same terms (gather reads)
#define SWISH_TF_BINDING_NORMAL_OFFSETS 3     // uniform texel buffer R32_UINT: uint[N+1] (welded adjacency)
#define SWISH_TF_BINDING_NORMAL_TRIANGLES 4   // uniform texel buffer R32_UINT
#define SWISH_TF_BINDING_TANGENT_OFFSETS 5    // uniform texel buffer R32_UINT: uint[N+1] (own triangles)
#define SWISH_TF_BINDING_TANGENT_TRIANGLES 6  // uniform texel buffer R32_UINT
#define SWISH_TF_BINDING_NORMALS_OUT 7        // storage buffer: float[instance][N][3]
#define SWISH_TF_BINDING_TANGENTS_OUT 8       // storage buffer: vec4[instance][N]
#define SWISH_TF_BINDING_COUNT 9

// triangle_frames.comp: one thread per triangle, looping over the instances.
struct TriangleFramesParams {
  SWISH_TF_ADDRESS uvs;        // float[N][2] (ignored when hasUvs == 0)
  SWISH_TF_ADDRESS triangles;  // uint[T][3]
  uint vertexCount;
  uint triangleCount;
  uint instanceCount;
  uint hasUvs;
};

// vertex_frames_gather.comp: one thread per (vertex, instance), summing the triangle terms over the
// vertex's adjacency in the order of core/mesh_frames.cpp.
struct VertexFramesGatherParams {
  uint vertexCount;
  uint triangleCount;
  uint instanceCount;
  uint hasUvs;
};

#ifdef __cplusplus
static_assert(sizeof(TriangleFramesParams) == 2 * 8 + 16);
static_assert(sizeof(VertexFramesGatherParams) == 16);
}  // namespace swish::gpu::layout
#endif
#undef SWISH_TF_ADDRESS

#endif  // SWISH_TRIANGLE_FRAMES_LAYOUT_H
