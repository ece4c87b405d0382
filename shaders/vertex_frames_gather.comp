#version 460
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
#extension GL_GOOGLE_include_directive : require
#include "swish_frame_math.glsl"
#include "swish_triangle_frames_layout.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { VertexFramesGatherParams p; };
layout(set = 0, binding = SWISH_TF_BINDING_TERMS) uniform samplerBuffer terms;     // as vec4s
layout(set = 0, binding = SWISH_TF_BINDING_TERMS_Z) uniform samplerBuffer termsZ;  // as floats
layout(set = 0, binding = SWISH_TF_BINDING_NORMAL_OFFSETS) uniform usamplerBuffer normalOffsets;
layout(set = 0, binding = SWISH_TF_BINDING_FRAME_TRIANGLES) uniform usamplerBuffer frameTriangles;
layout(set = 0, binding = SWISH_TF_BINDING_NORMALS_OUT, std430) writeonly buffer NormalsOut { float normalsOut[]; };
layout(set = 0, binding = SWISH_TF_BINDING_TANGENTS_OUT, std430) writeonly buffer TangentsOut { vec4 tangentsOut[]; };

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
  normalsOut[3u * o] = nrm.x;
  normalsOut[3u * o + 1u] = nrm.y;
  normalsOut[3u * o + 2u] = nrm.z;
  tangentsOut[o] = tangent;
}
