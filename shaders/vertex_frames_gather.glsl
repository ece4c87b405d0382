// vertex_frames_gather.comp and vertex_frames_gather_store64.comp (the shader code of both).
// Second half of the two-pass tangent frames: one thread per (vertex, instance) sums the triangle
// terms written by triangle_frames.comp over the vertex's precomputed welded adjacency, in the
// adjacency order, which is the order of core/mesh_frames.cpp (computeVertexFrames, called by
// runtime/reference_tangent_frames.cpp): every triangle's face term into the normal sum, and the UV
// terms of the vertex's own triangles (the entries without SWISH_NOT_OWN_TRIANGLE, the CPU's tangent
// adjacency in its order) into the tangent and bitangent sums. No float atomics; every sum runs in the
// CPU's order on the CPU's per-triangle values, so the result is the CPU's up to the square roots and
// divisions of the final normalisation.
//
// One walk serves both sums (the CPU walks two lists): per entry one index and the terms, 2 vec4 + 1
// float texel fetches. Everything this thread reads per instance comes as texel fetches and the frames
// go out through storage buffers, the pass's descriptor set (binding numbers in
// swish_triangle_frames_layout.h): on lavapipe a vec4 texel fetch costs what one scalar load through a
// buffer address costs (descriptor_binding.hpp), and this gather is the per-instance hot loop.
//
// Stores: where the device has shaderInt64, TangentFramesPass uses vertex_frames_gather_store64.comp,
// this code storing the tangent as two 64-bit words and the normal (3 floats from float 3o) as one
// 64-bit word and a float, the word on the 8-byte aligned pair (x,y for even o, y,z for odd o; selects,
// not branches): 4 stores instead of 7, same bits (docs/performance.md, "Tangent frames").
#include "swish_frame_math.glsl"
#include "swish_triangle_frames_layout.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { VertexFramesGatherParams p; };
layout(set = 0, binding = SWISH_TF_BINDING_TERMS) uniform samplerBuffer terms;     // as vec4s
layout(set = 0, binding = SWISH_TF_BINDING_TERMS_Z) uniform samplerBuffer termsZ;  // as floats
layout(set = 0, binding = SWISH_TF_BINDING_NORMAL_OFFSETS) uniform usamplerBuffer normalOffsets;
layout(set = 0, binding = SWISH_TF_BINDING_FRAME_TRIANGLES) uniform usamplerBuffer frameTriangles;
layout(set = 0, binding = SWISH_TF_BINDING_NORMALS_OUT, std430) writeonly buffer NormalsOut { float normalsOut[]; };
#ifdef SWISH_TF_STORE64
// The normals buffer as 64-bit words too (aliasing one binding); the tangents as pairs of them.
layout(set = 0, binding = SWISH_TF_BINDING_NORMALS_OUT, std430) writeonly buffer NormalsOut64 { uint64_t normalsOut64[]; };
layout(set = 0, binding = SWISH_TF_BINDING_TANGENTS_OUT, std430) writeonly buffer TangentsOut { u64vec2 tangentsOut[]; };
uint64_t floatPair(float lo, float hi) { return packUint2x32(uvec2(floatBitsToUint(lo), floatBitsToUint(hi))); }
#else
layout(set = 0, binding = SWISH_TF_BINDING_TANGENTS_OUT, std430) writeonly buffer TangentsOut { vec4 tangentsOut[]; };
#endif

void main() {
  const uint v = gl_GlobalInvocationID.x;
  const uint instance = gl_GlobalInvocationID.y;
  if (v >= p.vertexCount || instance >= p.instanceCount) return;
  const int instanceFloats = int(SWISH_TERMS_INSTANCE_FLOATS(p.triangleCount));
  const int pairBase = int(instance) * instanceFloats / 4, zBase = int(instance) * instanceFloats + 8 * int(p.triangleCount);

  precise vec3 nsum = vec3(0.0), tsum = vec3(0.0), bsum = vec3(0.0);
  const int end = int(texelFetch(normalOffsets, int(v) + 1).x);
  for (int i = int(texelFetch(normalOffsets, int(v)).x); i < end; ++i) {
    const uint entry = texelFetch(frameTriangles, i).x;
    const int t = int(entry & ~SWISH_NOT_OWN_TRIANGLE);
    const vec4 a = texelFetch(terms, pairBase + 2 * t), b = texelFetch(terms, pairBase + 2 * t + 1);
    nsum = nsum + a.xyz;
    // A select, not a branch: lavapipe runs both sides for the whole 8-lane group anyway.
    const bool own = (entry & SWISH_NOT_OWN_TRIANGLE) == 0u;
    tsum = own ? tsum + vec3(a.w, b.xy) : tsum;
    bsum = own ? bsum + vec3(b.zw, texelFetch(termsZ, zBase + t).x) : bsum;
  }
  vec3 nrm;
  vec4 tangent;
  finishVertexFrame(nsum, tsum, bsum, nrm, tangent);

  const uint o = instance * p.vertexCount + v;
#ifdef SWISH_TF_STORE64
  const bool odd = (o & 1u) != 0u;
  normalsOut64[(3u * o + (o & 1u)) / 2u] = odd ? floatPair(nrm.y, nrm.z) : floatPair(nrm.x, nrm.y);
  normalsOut[odd ? 3u * o : 3u * o + 2u] = odd ? nrm.x : nrm.z;
  tangentsOut[o] = u64vec2(floatPair(tangent.x, tangent.y), floatPair(tangent.z, tangent.w));
#else
  normalsOut[3u * o] = nrm.x;
  normalsOut[3u * o + 1u] = nrm.y;
  normalsOut[3u * o + 2u] = nrm.z;
  tangentsOut[o] = tangent;
#endif
}
