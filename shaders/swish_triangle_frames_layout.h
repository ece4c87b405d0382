// Push-constant blocks of the two-pass tangent frames (triangle_frames.comp, then
// vertex_frames_gather.comp), shared by GLSL and C++ like swish_layouts.h (which it includes for the
// address type): GLSL sees the addresses as uvec2, C++ as swish::gpu::layout::Address.
//
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

// triangle_frames.comp: one thread per triangle, looping over the instances.
struct TriangleFramesParams {
  SWISH_TF_ADDRESS positions;  // float[instanceCount][N][3]
  SWISH_TF_ADDRESS uvs;        // float[N][2] (ignored when hasUvs == 0)
  SWISH_TF_ADDRESS triangles;  // uint[T][3]
  SWISH_TF_ADDRESS termsOut;   // vec4[instanceCount][T][3]
  uint vertexCount;
  uint triangleCount;
  uint instanceCount;
  uint hasUvs;
};

// vertex_frames_gather.comp: one thread per (vertex, instance), summing the triangle terms over the
// vertex's adjacency in the order of core/mesh_frames.cpp.
struct VertexFramesGatherParams {
  SWISH_TF_ADDRESS terms;             // vec4[instanceCount][T][3]
  SWISH_TF_ADDRESS normalOffsets;     // uint[N+1]  (welded adjacency)
  SWISH_TF_ADDRESS normalTriangles;   // uint[]
  SWISH_TF_ADDRESS tangentOffsets;    // uint[N+1]  (own triangles)
  SWISH_TF_ADDRESS tangentTriangles;  // uint[]
  SWISH_TF_ADDRESS normalsOut;        // float[instanceCount][N][3]
  SWISH_TF_ADDRESS tangentsOut;       // float[instanceCount][N][4]
  uint vertexCount;
  uint triangleCount;
  uint instanceCount;
  uint hasUvs;
};

#ifdef __cplusplus
static_assert(sizeof(TriangleFramesParams) == 4 * 8 + 16);
static_assert(sizeof(VertexFramesGatherParams) == 7 * 8 + 16);
}  // namespace swish::gpu::layout
#endif
#undef SWISH_TF_ADDRESS

#endif  // SWISH_TRIANGLE_FRAMES_LAYOUT_H
