// triangle_frames.comp and triangle_frames_store64.comp (the shader code of both).
// First half of the two-pass tangent frames: each triangle's face-normal term cross(e1, e2) and UV
// tangent/bitangent terms, computed ONCE per triangle and instance into a buffer (layout in
// swish_triangle_frames_layout.h), instead of once per adjacent vertex (about 6 times, and again for
// the tangent sums) as the single-pass tangent_frames.comp does. vertex_frames_gather.comp then sums
// them per vertex in the order of core/mesh_frames.cpp. The formulas are those of computeVertexFrames
// in its operation order, `precise` (no FMA), so the stored terms equal what the CPU adds bit for bit.
//
// One thread per triangle, looping over the instances: the triangle's corner indices and UV terms
// (instance-independent) are loaded and computed once for all instances. The per-instance streams go
// through the pass's descriptor set (binding numbers in swish_triangle_frames_layout.h): positions are
// fetched as texels and the terms stored as nine floats of a storage buffer, the cheap ways on
// lavapipe (descriptor_binding.hpp): lavapipe stores lane by lane and float by float, so nine floats
// cost 3/4 of three padded vec4s.
//
// Stores: where the device has shaderInt64, TangentFramesPass uses triangle_frames_store64.comp, this
// code storing the first eight floats as four 64-bit words (same bits; the instance blocks start at a
// multiple of 4 floats) and B.z as a float: 5 stores per triangle instead of 9 (measured in
// docs/performance.md, "Tangent frames"; fetching positions as RGB32 texels was no faster).
#include "swish_buffers.glsl"
#include "swish_frame_math.glsl"
#include "swish_triangle_frames_layout.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { TriangleFramesParams p; };
layout(set = 0, binding = SWISH_TF_BINDING_POSITIONS) uniform samplerBuffer positionTexels;  // float[instance][N][3]
layout(set = 0, binding = SWISH_TF_BINDING_TERMS_OUT, std430) writeonly buffer TermsOut { float termsOut[]; };
#ifdef SWISH_TF_STORE64
// The same buffer as 64-bit words (aliasing one binding).
layout(set = 0, binding = SWISH_TF_BINDING_TERMS_OUT, std430) writeonly buffer TermsOut64 { uint64_t termsOut64[]; };
uint64_t floatPair(float lo, float hi) { return packUint2x32(uvec2(floatBitsToUint(lo), floatBitsToUint(hi))); }
#endif

vec3 position(uint base, uint corner) {
  const int i = int(base + 3u * corner);
  return vec3(texelFetch(positionTexels, i).x, texelFetch(positionTexels, i + 1).x, texelFetch(positionTexels, i + 2).x);
}

void main() {
  const uint t = gl_GlobalInvocationID.x;
  if (t >= p.triangleCount) return;
  UintsIn tris = UintsIn(p.triangles);
  const uint c0 = tris.v[3u * t], c1 = tris.v[3u * t + 1u], c2 = tris.v[3u * t + 2u];

  const bool hasUvs = p.hasUvs != 0u;
  precise vec2 d1 = vec2(0.0), d2 = vec2(0.0);
  precise float r = 0.0;
  if (hasUvs) {
    FloatsIn uvs = FloatsIn(p.uvs);
    const vec2 uv0 = vec2(uvs.v[2u * c0], uvs.v[2u * c0 + 1u]);
    d1 = vec2(uvs.v[2u * c1], uvs.v[2u * c1 + 1u]) - uv0;
    d2 = vec2(uvs.v[2u * c2], uvs.v[2u * c2 + 1u]) - uv0;
    r = d1.x * d2.y - d2.x * d1.y;
  }
  // core/mesh_frames.cpp skips a triangle whose UV determinant is 0 or not finite.
  const bool usable = hasUvs && r != 0.0 && isFinite(r);

  const uint instanceFloats = SWISH_TERMS_INSTANCE_FLOATS(p.triangleCount);
  for (uint instance = 0u; instance < p.instanceCount; ++instance) {
    const uint base = instance * p.vertexCount * 3u;
    const vec3 p0 = position(base, c0);
    precise vec3 e1 = position(base, c1) - p0;
    precise vec3 e2 = position(base, c2) - p0;
    const vec3 n = crossCpu(e1, e2);
    // Zero where the CPU skips the triangle's UV terms (see swish_triangle_frames_layout.h).
    precise vec3 tangentTerm = vec3(0.0), bitangentTerm = vec3(0.0);
    if (usable) {
      tangentTerm = (e1 * d2.y - e2 * d1.y) / r;
      bitangentTerm = (e2 * d1.x - e1 * d2.x) / r;
    }
#ifdef SWISH_TF_STORE64
    const uint o64 = instance * (instanceFloats / 2u) + 4u * t;
    termsOut64[o64] = floatPair(n.x, n.y);
    termsOut64[o64 + 1u] = floatPair(n.z, tangentTerm.x);
    termsOut64[o64 + 2u] = floatPair(tangentTerm.y, tangentTerm.z);
    termsOut64[o64 + 3u] = floatPair(bitangentTerm.x, bitangentTerm.y);
#else
    const uint o = instance * instanceFloats + 8u * t;
    termsOut[o] = n.x;
    termsOut[o + 1u] = n.y;
    termsOut[o + 2u] = n.z;
    termsOut[o + 3u] = tangentTerm.x;
    termsOut[o + 4u] = tangentTerm.y;
    termsOut[o + 5u] = tangentTerm.z;
    termsOut[o + 6u] = bitangentTerm.x;
    termsOut[o + 7u] = bitangentTerm.y;
#endif
    termsOut[instance * instanceFloats + 8u * p.triangleCount + t] = bitangentTerm.z;
  }
}
