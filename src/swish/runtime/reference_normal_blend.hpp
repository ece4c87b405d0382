#pragma once
// CPU reference of shaders/normal_map_blend.comp: the temporal filter's blend of a newly selected,
// decoded map into a character's normal map, stored as snorm16 X, Y (VK_FORMAT_R16G16_SNORM):
//   prev = max(p / 32767, -1);  d = max(c / 127, -1)
//   out  = prev * (1 - alpha) + d * alpha           (GLSL mix, in that order)
//   stored = round(clamp(out, -1, 1) * 32767)       (NaN stores 0)
// Vulkan lets a device round float -> snorm either way near a tie, so the GPU matches within 1 LSB.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "swish/runtime/reference_vq_decode.hpp"

namespace swish::runtime {

struct BlendedNormalMap {
  uint32_t width = 0, height = 0;
  std::vector<int16_t> xy;  // (y * width + x) * 2 + {0: X, 1: Y}, snorm16

  static BlendedNormalMap zeros(uint32_t width, uint32_t height) {
    return {width, height, std::vector<int16_t>(size_t(width) * height * 2, 0)};
  }
};

inline float snorm16ToFloat(int16_t v) { return std::max(float(v) / 32767.f, -1.f); }
// The map's X, Y as floats in [-1, 1], in its layout (for PNG export and comparison with baked maps).
inline std::vector<float> xyAsFloat(const BlendedNormalMap& map) {
  std::vector<float> xy(map.xy.size());
  for (size_t i = 0; i < xy.size(); ++i) xy[i] = snorm16ToFloat(map.xy[i]);
  return xy;
}
int16_t floatToSnorm16(float f);

// Blends `decoded` into `map` in place. Sizes must match (Error otherwise).
void referenceNormalBlend(BlendedNormalMap& map, const DecodedNormalMap& decoded, float alpha);

}  // namespace swish::runtime
