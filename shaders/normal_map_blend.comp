#version 460
// Temporal blend of each character's newly selected (decoded) map into its normal map:
// out = mix(prev, decoded, alpha), per character one layer of an RG16_SNORM 2D array image.
// prev and out are the layers of the previous and current frame-in-flight images (the same image
// when there is one frame in flight: each texel is read then written by the same invocation).
// Conforms to runtime/reference_normal_blend.cpp: decoded snorm8 -> max(c / 127, -1); mix written
// as prev * (1 - alpha) + decoded * alpha; storage rounds to snorm16 (within 1 LSB, rounding is the
// device's choice). Z is not stored: renderers reconstruct it as sqrt(max(0, 1 - X^2 - Y^2)).
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(push_constant) uniform Push { NormalMapBlendParams p; };
layout(set = 0, binding = 0, rg16_snorm) uniform readonly image2DArray prevMaps;
layout(set = 0, binding = 1, rg16_snorm) uniform writeonly image2DArray outMaps;

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Characters {
  NormalMapBlendCharacter c[];
};

float snorm8(uint byteValue) {
  const int c = int(byteValue << 24) >> 24;  // sign-extend
  return max(float(c) / 127.0, -1.0);
}

void main() {
  const uvec3 id = gl_GlobalInvocationID;
  if (id.x >= p.width || id.y >= p.height || id.z >= p.characterCount) return;
  const NormalMapBlendCharacter ch = Characters(p.characters).c[id.z];
  const uint texel = id.y * p.width + id.x;
  const uint word = UintsIn(p.decoded).v[(ch.decodedSlot * p.width * p.height + texel) / 2u];
  const uint half16 = (texel % 2u == 0u) ? (word & 0xFFFFu) : (word >> 16);
  const vec2 decoded = vec2(snorm8(half16 & 0xFFu), snorm8(half16 >> 8));
  const ivec3 at = ivec3(id);
  const vec2 prev = imageLoad(prevMaps, at).xy;
  precise vec2 blended = prev * (1.0 - ch.alpha) + decoded * ch.alpha;
  imageStore(outMaps, at, vec4(blended, 0.0, 0.0));
}
