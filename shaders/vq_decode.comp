#version 460
// VQ decode of normal-map database maps into decoded slots: each map the frame recorder has not got
// decoded yet is decoded ONCE into its own slot, however many characters chose it (and the slots keep
// their maps across frames: database maps are constant). One thread per pair of horizontally adjacent
// texels: they lie in the same 4x4 block, so their 4 bytes (X0 Y0 X1 Y1) are one word of the codebook
// entry and decoding is a lossless word copy (conforms exactly to runtime/reference_vq_decode.cpp).
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { VqDecodeParams p; };

void main() {
  const uint pairsPerMap = p.width * p.height / 2u;
  const uint pair = gl_GlobalInvocationID.x;
  const uint job = gl_GlobalInvocationID.y;
  if (pair >= pairsPerMap || job >= p.jobCount) return;
  const uint x = (2u * pair) % p.width, y = (2u * pair) / p.width;
  const uint map = UintsIn(p.jobMaps).v[job];
  const uint slot = (p.jobSlots == uvec2(0u)) ? job : UintsIn(p.jobSlots).v[job];
  const uint block = (y / 4u) * (p.width / 4u) + x / 4u;
  const uint indexPos = map * (p.width / 4u) * (p.height / 4u) + block;
  const uint indexWord = UintsIn(p.indices).v[indexPos / 2u];
  const uint entry = (indexPos % 2u == 0u) ? (indexWord & 0xFFFFu) : (indexWord >> 16);
  const uint texel = (y % 4u) * 4u + x % 4u;  // even: x is even
  uint word = 0u;
  if (entry < p.codebookSize) word = UintsIn(p.codebook).v[(entry * 16u + texel) / 2u];
  UintsOut(p.decodedOut).v[slot * pairsPerMap + pair] = word;
}
