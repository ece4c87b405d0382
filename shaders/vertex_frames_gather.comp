#version 460
// Second half of the two-pass tangent frames: one thread per (vertex, instance) sums the triangle
// terms written by triangle_frames.comp over the vertex's precomputed adjacency (welded for normals,
// own triangles for tangents), in the adjacency order, which is the order of core/mesh_frames.cpp
// (computeVertexFrames, called by runtime/reference_tangent_frames.cpp). No float atomics; every sum
// runs in the CPU's order on the CPU's per-triangle values, so the result is the CPU's up to the
// square roots and divisions of the final normalisation.
//
// Everything this thread reads per instance (the terms and the adjacency it walks) comes as texel
// fetches and the frames go out through storage buffers, the pass's descriptor set (binding numbers in
// swish_triangle_frames_layout.h): on lavapipe a vec4 texel fetch costs what one scalar load through a
// buffer address costs (descriptor_binding.hpp), and this gather is the per-instance hot loop.
#extension GL_GOOGLE_include_directive : require
#include "swish_frame_math.glsl"
#include "swish_triangle_frames_layout.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { VertexFramesGatherParams p; };
layout(set = 0, binding = SWISH_TF_BINDING_TERMS) uniform samplerBuffer terms;  // vec4[instance][T][3]
layout(set = 0, binding = SWISH_TF_BINDING_NORMAL_OFFSETS) uniform usamplerBuffer normalOffsets;
layout(set = 0, binding = SWISH_TF_BINDING_NORMAL_TRIANGLES) uniform usamplerBuffer normalTriangles;
layout(set = 0, binding = SWISH_TF_BINDING_TANGENT_OFFSETS) uniform usamplerBuffer tangentOffsets;
layout(set = 0, binding = SWISH_TF_BINDING_TANGENT_TRIANGLES) uniform usamplerBuffer tangentTriangles;
layout(set = 0, binding = SWISH_TF_BINDING_NORMALS_OUT, std430) writeonly buffer NormalsOut { float normalsOut[]; };
layout(set = 0, binding = SWISH_TF_BINDING_TANGENTS_OUT, std430) writeonly buffer TangentsOut { vec4 tangentsOut[]; };

void main() {
  const uint v = gl_GlobalInvocationID.x;
  const uint instance = gl_GlobalInvocationID.y;
  if (v >= p.vertexCount || instance >= p.instanceCount) return;
  const int termBase = int(instance * p.triangleCount * SWISH_TRIANGLE_TERM_VEC4S);

  precise vec3 nsum = vec3(0.0);
  const int nEnd = int(texelFetch(normalOffsets, int(v) + 1).x);
  for (int i = int(texelFetch(normalOffsets, int(v)).x); i < nEnd; ++i)
    nsum = nsum + texelFetch(terms, termBase + SWISH_TRIANGLE_TERM_VEC4S * int(texelFetch(normalTriangles, i).x)).xyz;

  precise vec3 tsum = vec3(0.0), bsum = vec3(0.0);
  if (p.hasUvs != 0u) {
    const int tEnd = int(texelFetch(tangentOffsets, int(v) + 1).x);
    for (int i = int(texelFetch(tangentOffsets, int(v)).x); i < tEnd; ++i) {
      const int o = termBase + SWISH_TRIANGLE_TERM_VEC4S * int(texelFetch(tangentTriangles, i).x);
      const vec4 tangentTerm = texelFetch(terms, o + 1);
      if (tangentTerm.w == 0.0) continue;  // a triangle the CPU definition skips (degenerate UVs)
      tsum = tsum + tangentTerm.xyz;
      bsum = bsum + texelFetch(terms, o + 2).xyz;
    }
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
