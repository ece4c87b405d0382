#version 460
// Normals and tangents of deformed meshes: one thread per (vertex, instance), GATHERING over the
// precomputed vertex -> triangle adjacency (welded for normals, own triangles for tangents), so no
// float atomics are needed and every sum runs in the same order as the CPU definition,
// core/mesh_frames.cpp (computeVertexFrames), which runtime/reference_tangent_frames.cpp calls.
// Every formula below is written out in that file's operation order; `precise` forbids FMA contraction.
// TangentFramesPass uses this single-pass kernel when the caller gives no triangle-terms buffer; with
// one it runs triangle_frames.comp + vertex_frames_gather.comp, which compute each triangle's terms
// once instead of once per adjacent vertex (same values, same sums).
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_frame_math.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { TangentFramesParams p; };

FloatsIn positions;
uint base;  // first float of this instance's positions
vec3 corner(UintsIn tris, uint t, uint k) {
  const uint i = base + 3u * tris.v[3u * t + k];
  return vec3(positions.v[i], positions.v[i + 1u], positions.v[i + 2u]);
}

void main() {
  const uint v = gl_GlobalInvocationID.x;
  const uint instance = gl_GlobalInvocationID.y;
  if (v >= p.vertexCount || instance >= p.instanceCount) return;
  positions = FloatsIn(p.positions);
  base = instance * p.vertexCount * 3u;
  UintsIn tris = UintsIn(p.triangles);

  UintsIn nOff = UintsIn(p.normalOffsets);
  UintsIn nTri = UintsIn(p.normalTriangles);
  precise vec3 nsum = vec3(0.0);
  for (uint i = nOff.v[v]; i < nOff.v[v + 1u]; ++i) {
    const uint t = nTri.v[i];
    precise vec3 p0 = corner(tris, t, 0u);
    precise vec3 e1 = corner(tris, t, 1u) - p0;
    precise vec3 e2 = corner(tris, t, 2u) - p0;
    nsum = nsum + crossCpu(e1, e2);
  }

  precise vec3 tsum = vec3(0.0), bsum = vec3(0.0);
  if (p.hasUvs != 0u) {
    FloatsIn uvs = FloatsIn(p.uvs);
    UintsIn tOff = UintsIn(p.tangentOffsets);
    UintsIn tTri = UintsIn(p.tangentTriangles);
    for (uint i = tOff.v[v]; i < tOff.v[v + 1u]; ++i) {
      const uint t = tTri.v[i];
      precise vec3 p0 = corner(tris, t, 0u);
      precise vec3 e1 = corner(tris, t, 1u) - p0;
      precise vec3 e2 = corner(tris, t, 2u) - p0;
      const uint c0 = tris.v[3u * t], c1 = tris.v[3u * t + 1u], c2 = tris.v[3u * t + 2u];
      const vec2 uv0 = vec2(uvs.v[2u * c0], uvs.v[2u * c0 + 1u]);
      precise vec2 d1 = vec2(uvs.v[2u * c1], uvs.v[2u * c1 + 1u]) - uv0;
      precise vec2 d2 = vec2(uvs.v[2u * c2], uvs.v[2u * c2 + 1u]) - uv0;
      precise float r = d1.x * d2.y - d2.x * d1.y;
      if (r == 0.0 || !isFinite(r)) continue;
      tsum = tsum + (e1 * d2.y - e2 * d1.y) / r;
      bsum = bsum + (e2 * d1.x - e1 * d2.x) / r;
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
