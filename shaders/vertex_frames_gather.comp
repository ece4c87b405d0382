#version 460
// Second half of the two-pass tangent frames: one thread per (vertex, instance) sums the triangle
// terms written by triangle_frames.comp over the vertex's precomputed adjacency (welded for normals,
// own triangles for tangents), in the adjacency order, which is the order of core/mesh_frames.cpp
// (computeVertexFrames, called by runtime/reference_tangent_frames.cpp). No float atomics; every sum
// runs in the CPU's order on the CPU's per-triangle values, so the result is the CPU's up to the
// square roots and divisions of the final normalisation.
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_frame_math.glsl"
#include "swish_triangle_frames_layout.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { VertexFramesGatherParams p; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4sIn { vec4 v[]; };

void main() {
  const uint v = gl_GlobalInvocationID.x;
  const uint instance = gl_GlobalInvocationID.y;
  if (v >= p.vertexCount || instance >= p.instanceCount) return;
  Vec4sIn terms = Vec4sIn(p.terms);
  const uint termBase = instance * p.triangleCount * SWISH_TRIANGLE_TERM_VEC4S;

  UintsIn nOff = UintsIn(p.normalOffsets);
  UintsIn nTri = UintsIn(p.normalTriangles);
  precise vec3 nsum = vec3(0.0);
  for (uint i = nOff.v[v]; i < nOff.v[v + 1u]; ++i)
    nsum = nsum + terms.v[termBase + SWISH_TRIANGLE_TERM_VEC4S * nTri.v[i]].xyz;

  precise vec3 tsum = vec3(0.0), bsum = vec3(0.0);
  if (p.hasUvs != 0u) {
    UintsIn tOff = UintsIn(p.tangentOffsets);
    UintsIn tTri = UintsIn(p.tangentTriangles);
    for (uint i = tOff.v[v]; i < tOff.v[v + 1u]; ++i) {
      const uint o = termBase + SWISH_TRIANGLE_TERM_VEC4S * tTri.v[i];
      const vec4 tangentTerm = terms.v[o + 1u];
      if (tangentTerm.w == 0.0) continue;  // a triangle the CPU definition skips (degenerate UVs)
      tsum = tsum + tangentTerm.xyz;
      bsum = bsum + terms.v[o + 2u].xyz;
    }
  }
  vec3 nrm;
  vec4 tangent;
  finishVertexFrame(nsum, tsum, bsum, nrm, tangent);

  FloatsOut normalsOut = FloatsOut(p.normalsOut);
  FloatsOut tangentsOut = FloatsOut(p.tangentsOut);
  const uint o = instance * p.vertexCount + v;
  normalsOut.v[3u * o] = nrm.x;
  normalsOut.v[3u * o + 1u] = nrm.y;
  normalsOut.v[3u * o + 2u] = nrm.z;
  tangentsOut.v[4u * o] = tangent.x;
  tangentsOut.v[4u * o + 1u] = tangent.y;
  tangentsOut.v[4u * o + 2u] = tangent.z;
  tangentsOut.v[4u * o + 3u] = tangent.w;
}
