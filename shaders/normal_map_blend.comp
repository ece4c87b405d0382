#version 460
// Temporal blend of each character's newly selected (decoded) map into its normal map:
// out = mix(prev, decoded, alpha), per character one layer of an RG16_SNORM 2D array image.
// prev and out are the layers of the previous and current frame-in-flight images (the same image
// when there is one frame in flight: each texel is read then written by the same invocation).
// Conforms to runtime/reference_normal_blend.cpp: decoded snorm8 -> max(c / 127, -1); mix written
// as prev * (1 - alpha) + decoded * alpha; storage rounds to snorm16 (within 1 LSB, rounding is the
// device's choice). Z is not stored: renderers reconstruct it as sqrt(max(0, 1 - X^2 - Y^2)).
//
// One invocation per 4x4 block of one character (a VQ block: maps are multiples of 4): the
// character's slot and alpha are loaded once for 16 texels, and each block row of decoded texels is
// ONE texel fetch (R32G32_UINT: 4 texels of 2 snorm8 bytes). One invocation per texel measured 2.2x
// slower on lavapipe, which runs invocations 8 at a time on a CPU core and pays per-lane costs for every
// buffer load and per invocation for the indexing.
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { NormalMapBlendParams p; };
layout(set = 0, binding = 0, rg16_snorm) uniform readonly image2DArray prevMaps;
layout(set = 0, binding = 1, rg16_snorm) uniform writeonly image2DArray outMaps;
layout(set = 0, binding = 2) uniform usamplerBuffer decodedRows;  // uvec2[slot][height][width / 4]

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Characters {
  NormalMapBlendCharacter c[];
};

float snorm8(uint byteValue) {
  const int c = int(byteValue << 24) >> 24;  // sign-extend
  return max(float(c) / 127.0, -1.0);
}

void main() {
  const uint blocksX = p.width / 4u, blocks = blocksX * (p.height / 4u);
  const uint block = gl_GlobalInvocationID.x;
  const uint character = gl_GlobalInvocationID.z;
  if (block >= blocks || character >= p.characterCount) return;
  const NormalMapBlendCharacter ch = Characters(p.characters).c[character];
  const uint x0 = (block % blocksX) * 4u, y0 = (block / blocksX) * 4u;
  const uint rowsPerSlot = p.height * blocksX;
  for (uint r = 0u; r < 4u; ++r) {
    const uint y = y0 + r;
    const uvec2 words = texelFetch(decodedRows, int(ch.decodedSlot * rowsPerSlot + y * blocksX + x0 / 4u)).xy;
    for (uint i = 0u; i < 4u; ++i) {
      const uint half16 = (words[i / 2u] >> (16u * (i % 2u))) & 0xFFFFu;
      const vec2 decoded = vec2(snorm8(half16 & 0xFFu), snorm8(half16 >> 8));
      const ivec3 at = ivec3(int(x0 + i), int(y), int(character));
      const vec2 prev = imageLoad(prevMaps, at).xy;
      precise vec2 blended = prev * (1.0 - ch.alpha) + decoded * ch.alpha;
      imageStore(outMaps, at, vec4(blended, 0.0, 0.0));
    }
  }
}
