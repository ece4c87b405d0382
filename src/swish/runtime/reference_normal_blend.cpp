#include "swish/runtime/reference_normal_blend.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish::runtime {

int16_t floatToSnorm16(float f) {
  if (std::isnan(f)) return 0;
  return int16_t(std::lround(std::clamp(f, -1.f, 1.f) * 32767.f));
}

void referenceNormalBlend(BlendedNormalMap& map, const DecodedNormalMap& decoded, float alpha) {
  if (map.width != decoded.width || map.height != decoded.height || map.xy.size() != decoded.xy.size())
    throw Error("normal-map blend: map " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                " and decoded map " + std::to_string(decoded.width) + "x" + std::to_string(decoded.height) +
                " differ in size");
  for (size_t i = 0; i < map.xy.size(); ++i) {
    const float prev = snorm16ToFloat(map.xy[i]);
    const float d = snorm8ToFloat(decoded.xy[i]);
    map.xy[i] = floatToSnorm16(prev * (1.f - alpha) + d * alpha);
  }
}

}  // namespace swish::runtime
