// Push-constant blocks and descriptor bindings of the two-pass tangent frames (triangle_frames.comp,
// then vertex_frames_gather.comp), shared by GLSL and C++ like swish_layouts.h (which it includes for
// the address type): GLSL sees the addresses as uvec2, C++ as swish::gpu::layout::Address.
//
// Both kernels use one descriptor set layout (TangentFramesPass::bindTwoPass); the per-instance
// streams are in it, model data read once per triangle stays behind addresses:
// Triangle terms (written by the triangle pass, read by the gather), for triangle t of an instance: the
// face normal term N = cross(e1, e2) of the triangle's edges from corner 0, the UV
// tangent term U = (e1 * d2.y - e2 * d1.y) / r and the UV bitangent term B = (e2 * d1.x - e1 * d2.x) / r,
// U = B = 0 where core/mesh_frames.cpp skips the triangle (r == 0 or not finite) or the mesh has no UVs
// (adding +0 to a sum that starts at +0 leaves it bit for bit as skipping does). Nine floats, no padding
// (on lavapipe each stored float costs the same, per lane). Instance i's terms are the
// SWISH_TERMS_INSTANCE_FLOATS(T) floats from float i * SWISH_TERMS_INSTANCE_FLOATS(T) (a multiple of 4):
//   vec4[T][2]: [2t] = (N.xyz, U.x), [2t + 1] = (U.yz, B.xy)
//   then float[T]: [t] = B.z
// The gather walks the vertex's welded (normal) adjacency once, with the triangles that are not the
// vertex's own marked by SWISH_NOT_OWN_TRIANGLE: they add to the normal sum only (the own triangles,
// core/mesh_frames.cpp's tangent adjacency, are a subsequence of the welded ones, in the same order).
#ifndef SWISH_TRIANGLE_FRAMES_LAYOUT_H
#define SWISH_TRIANGLE_FRAMES_LAYOUT_H

#include "swish_layouts.h"

#ifdef __cplusplus
namespace swish::gpu::layout {
#define SWISH_TF_ADDRESS Address
#else
#define SWISH_TF_ADDRESS uvec2
#endif

#define SWISH_TERMS_INSTANCE_FLOATS(triangleCount) ((((triangleCount) * 9u + 3u) / 4u) * 4u)
#define SWISH_NOT_OWN_TRIANGLE 0x80000000u  // flag of a welded adjacency entry (triangle index below it)

#define SWISH_TF_BINDING_POSITIONS 0          // uniform texel buffer R32_SFLOAT: float[instance][N][3]
#define SWISH_TF_BINDING_TERMS_OUT 1          // storage buffer: float[] (triangle pass writes the terms)
#define SWISH_TF_BINDING_TERMS 2              // uniform texel buffer R32G32B32A32_SFLOAT: the terms (gather: vec4 pairs)
#define SWISH_TF_BINDING_TERMS_Z 3            // uniform texel buffer R32_SFLOAT: the terms (gather: B.z floats)
#define SWISH_TF_BINDING_NORMAL_OFFSETS 4     // uniform texel buffer R32_UINT: uint[N+1] (welded adjacency)
#define SWISH_TF_BINDING_FRAME_TRIANGLES 5    // uniform texel buffer R32_UINT: welded adjacency, flagged
#define SWISH_TF_BINDING_NORMALS_OUT 6        // storage buffer: float[instance][N][3]
#define SWISH_TF_BINDING_TANGENTS_OUT 7       // storage buffer: vec4[instance][N]
#define SWISH_TF_BINDING_COUNT 8

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
