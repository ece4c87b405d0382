#include "swish/bake/bc5_baseline.hpp"

#include <squish.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace {
// One BC4 channel block (8 bytes: two endpoints, sixteen 3-bit indices), as the D3D/Vulkan spec
// decodes it. libsquish 1.15 (Debian's) compresses BC4/BC5 correctly but its decoder returns wrong
// values (0..240 gradient -> 71, 107, 71, 35, ...), so the baseline decodes by the specification.
void decodeBc4Block(const squish::u8* block, squish::u8 out[16]) {
  const int a0 = block[0], a1 = block[1];
  int palette[8] = {a0, a1};
  if (a0 > a1) {
    for (int i = 1; i <= 6; ++i) palette[i + 1] = ((7 - i) * a0 + i * a1 + 3) / 7;
  } else {
    for (int i = 1; i <= 4; ++i) palette[i + 1] = ((5 - i) * a0 + i * a1 + 2) / 5;
    palette[6] = 0;
    palette[7] = 255;
  }
  uint64_t bits = 0;
  for (int b = 0; b < 6; ++b) bits |= uint64_t(block[2 + b]) << (8 * b);
  for (int t = 0; t < 16; ++t) out[t] = squish::u8(palette[(bits >> (3 * t)) & 7]);
}
}  // namespace

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
  NormalMapImage out{map.width, map.height, std::vector<float>(texels * 2)};
  const uint32_t bw = (map.width + 3) / 4, bh = (map.height + 3) / 4;
  for (uint32_t by = 0; by < bh; ++by)
    for (uint32_t bx = 0; bx < bw; ++bx) {
      const squish::u8* block = blocks.data() + (size_t(by) * bw + bx) * 16;
      squish::u8 values[2][16];
      decodeBc4Block(block, values[0]);      // red = X
      decodeBc4Block(block + 8, values[1]);  // green = Y
      for (uint32_t t = 0; t < 16; ++t) {
        const uint32_t x = bx * 4 + t % 4, y = by * 4 + t / 4;
        if (x >= map.width || y >= map.height) continue;
        for (int c = 0; c < 2; ++c) out.xy[2 * (size_t(y) * map.width + x) + c] = float(values[c][t]) / 255.f * 2.f - 1.f;
      }
    }
  return out;
}

}  // namespace swish::bake
