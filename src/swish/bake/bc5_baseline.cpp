#include "swish/bake/bc5_baseline.hpp"

#include <squish.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

size_t bc5Bytes(uint32_t width, uint32_t height) {
  return size_t((width + 3) / 4) * size_t((height + 3) / 4) * 16;
}

NormalMapImage bc5RoundTrip(const NormalMapImage& map) {
  const size_t texels = size_t(map.width) * map.height;
  if (texels == 0 || map.xy.size() != texels * 2)
    throw Error("bc5 baseline: map of " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                " holds " + std::to_string(map.xy.size()) + " values");
  std::vector<squish::u8> rgba(texels * 4, 0);
  for (size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < 2; ++c) {
      const float v = std::clamp(map.xy[2 * t + c], -1.f, 1.f);
      rgba[4 * t + c] = squish::u8(std::lround((v * 0.5f + 0.5f) * 255.f));
    }
    rgba[4 * t + 3] = 255;
  }
  std::vector<squish::u8> blocks(bc5Bytes(map.width, map.height));
  squish::CompressImage(rgba.data(), int(map.width), int(map.height), blocks.data(), squish::kBc5);
  std::vector<squish::u8> decoded(texels * 4, 0);
  squish::DecompressImage(decoded.data(), int(map.width), int(map.height), blocks.data(), squish::kBc5);
  NormalMapImage out{map.width, map.height, std::vector<float>(texels * 2)};
  for (size_t t = 0; t < texels; ++t)
    for (int c = 0; c < 2; ++c) out.xy[2 * t + c] = float(decoded[4 * t + c]) / 255.f * 2.f - 1.f;
  return out;
}

}  // namespace swish::bake
