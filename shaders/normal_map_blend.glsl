// normal_map_blend.comp and normal_map_blend_store64.comp (the shader code of both).
// Temporal blend of each character's newly selected (decoded) map into its normal map:
// out = mix(prev, decoded, alpha), per character one layer of RG16_SNORM texels.
// The blend reads and writes the maps as BUFFERS of packed texels (uint32[layer][height][width]:
// snorm16 X | Y << 16, the memory layout of R16G16_SNORM), prev of the previous frame in flight, out of
// this one (the same buffer when there is one frame in flight: each texel is read then written by the
// same invocation); NormalMapBlendPass then copies out into the layers of the RG16_SNORM image array
// that renderers sample. Conforms to runtime/reference_normal_blend.cpp: decoded snorm8 ->
// max(c / 127, -1), prev snorm16 -> max(c / 32767, -1); mix written as prev * (1 - alpha) +
// decoded * alpha; rounded to snorm16 by packSnorm2x16 (within 1 LSB of the reference's lround).
// Why not the images themselves: on lavapipe a storage-image load or store of RG16_SNORM converts the
// format lane by lane; the buffers, the copy and the exact dispatch below are measurably faster
// (docs/performance.md, "Normal-map blend", for this and the choices below).
//
// Each character blends one layer: character c's own (layer c), or layers[c] where the pass is given a
// list (FrameRecorder leaves out characters without a map this frame).
//
// One invocation per column of ROWS x 4 texels of one character (ROWS block rows of 4 texels, a
// multiple of 4: maps are multiples of 4; NormalMapBlendPass picks 16, 8 or 4, the largest dividing the
// map height): the character's slot and alpha are loaded once for 4 * ROWS texels, and each row is ONE
// texel fetch of decoded texels (R32G32_UINT: 4 texels of 2 snorm8 bytes), ONE texel fetch of prev
// (R32G32B32A32_UINT: 4 packed texels) and ONE uvec4 store. Lavapipe runs invocations 8 at a time on a
// CPU core and pays per-lane costs for every buffer load and per invocation for the indexing and the
// character's (address) load, so fewer, fatter invocations win: one per texel was much slower, and 16
// rows beat 4.
//
// Stores: lavapipe stores lane by lane and word by word, so where the device has shaderInt64 the pass
// uses normal_map_blend_store64.comp, this code storing each row as two 64-bit words instead of four
// 32-bit ones (same bits, fewer stores).
//
// The dispatch is (block columns, height / ROWS, characters) with workgroups of ROW_GROUP block columns,
// a divisor of the block columns that NormalMapBlendPass picks (EXACT), so that no invocation falls
// outside the map and the shader needs no bounds check: on lavapipe a bounds check (an early return)
// puts every store under an execution mask, a load, select and store per lane and component instead
// of a store. Where the block columns have no usable
// divisor, the pass picks 64 and EXACT = false, and the bounds check is compiled in.
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;                  // ROW_GROUP
layout(constant_id = 1) const bool EXACT = true;  // the dispatch covers the block columns exactly
layout(constant_id = 2) const uint ROWS = 4u;      // texel rows per invocation (4, 8 or 16)
layout(push_constant) uniform Push { NormalMapBlendParams p; };
layout(set = 0, binding = 0) uniform usamplerBuffer prevRows;                 // uvec4[layer][height][width / 4]
#ifdef SWISH_BLEND_STORE64
layout(set = 0, binding = 1, std430) writeonly buffer OutRows { u64vec2 outRows[]; };  // the same layout
#else
layout(set = 0, binding = 1, std430) writeonly buffer OutRows { uvec4 outRows[]; };    // the same layout
#endif
layout(set = 0, binding = 2) uniform usamplerBuffer decodedRows;              // uvec2[slot][height][width / 4]

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Characters {
  NormalMapBlendCharacter c[];
};

float snorm8(uint byteValue) {
  const int c = int(byteValue << 24) >> 24;  // sign-extend
  return max(float(c) / 127.0, -1.0);
}

void main() {
  const uint blocksX = p.width / 4u;
  const uint bx = gl_GlobalInvocationID.x, y0 = gl_GlobalInvocationID.y * ROWS;
  const uint character = gl_GlobalInvocationID.z;  // the dispatch has characterCount layers
  if (!EXACT && bx >= blocksX) return;
  const NormalMapBlendCharacter ch = Characters(p.characters).c[character];
  // Characters at a quality level without normal maps are left out of the dispatch: the others name
  // their layers, and the left-out layers are neither read nor written.
  const uint layer = p.layers == uvec2(0u) ? character : UintsIn(p.layers).v[character];
  const uint rowsPerMap = p.height * blocksX;  // block rows of 4 texels
  for (uint r = 0u; r < ROWS; ++r) {
    const uint row = (y0 + r) * blocksX + bx;
    const uvec2 words = texelFetch(decodedRows, int(ch.decodedSlot * rowsPerMap + row)).xy;
    const uint at = layer * rowsPerMap + row;
    const uvec4 prev = texelFetch(prevRows, int(at));
    uvec4 blendedRow;
    for (uint i = 0u; i < 4u; ++i) {
      const uint half16 = (words[i / 2u] >> (16u * (i % 2u))) & 0xFFFFu;
      const vec2 decoded = vec2(snorm8(half16 & 0xFFu), snorm8(half16 >> 8));
      const vec2 prevXY = unpackSnorm2x16(prev[i]);  // clamp(c / 32767, -1, 1)
      precise vec2 blended = prevXY * (1.0 - ch.alpha) + decoded * ch.alpha;
      blendedRow[i] = packSnorm2x16(blended);
    }
#ifdef SWISH_BLEND_STORE64
    outRows[at] = u64vec2(packUint2x32(blendedRow.xy), packUint2x32(blendedRow.zw));
#else
    outRows[at] = blendedRow;
#endif
  }
}
