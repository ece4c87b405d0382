#include "swish/bake/compression/bc5_baseline.hpp"

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

// The map's texel count, after checking it holds two values for each.
size_t checkedTexels(const NormalMapImage& map) {
  const size_t texels = size_t(map.width) * map.height;
  if (texels == 0 || map.xy.size() != texels * 2)
    throw Error("bc5 baseline: map of " + std::to_string(map.width) + "x" + std::to_string(map.height) + " holds " +
                std::to_string(map.xy.size()) + " values");
  return texels;
}
}  // namespace

size_t bc5Bytes(uint32_t width, uint32_t height) { return size_t((width + 3) / 4) * size_t((height + 3) / 4) * 16; }

NormalMapImage bc5RoundTrip(const NormalMapImage& map) {
  const size_t texels = checkedTexels(map);
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
        for (int c = 0; c < 2; ++c)
          out.xy[2 * (size_t(y) * map.width + x) + c] = float(values[c][t]) / 255.f * 2.f - 1.f;
      }
    }
  return out;
}

std::pair<uint32_t, uint32_t> bc5SizeWithin(uint32_t width, uint32_t height, size_t bytes) {
  if (width == 0 || height == 0) return {0, 0};
  // Scale both sides by one factor, each rounded down to whole 4x4 blocks: then (w / 4) (h / 4) 16 <=
  // scale^2 * bc5Bytes(width, height) = bytes, up to the last-place rounding of the square root, which
  // the one step back corrects.
  const double scale = std::sqrt(double(bytes) / double(bc5Bytes(width, height)));
  auto side = [&](uint32_t n) { return std::min(n, uint32_t(std::floor(double(n) * scale / 4.0)) * 4u); };
  uint32_t w = side(width), h = side(height);
  if (w >= 4 && h >= 4 && bc5Bytes(w, h) > bytes) w -= 4, h -= 4;
  return (w >= 4 && h >= 4) ? std::pair{w, h} : std::pair{0u, 0u};
}

namespace {
// Area-weighted box filter of one line of n two-channel samples down to m: output o averages the
// input span [o n / m, (o + 1) n / m), partly covered samples by their covered fraction.
// in(i, c) reads sample i's channel c; out(o, c, value) writes.
template <class In, class Out>
void boxDown(uint32_t n, uint32_t m, In in, Out out) {
  const double ratio = double(n) / double(m);
  for (uint32_t o = 0; o < m; ++o) {
    const double a = o * ratio, b = (o + 1) * ratio;
    double sum[2] = {0, 0};
    for (uint32_t i = uint32_t(a); i < n && double(i) < b; ++i) {
      const double w = std::min(b, double(i + 1)) - std::max(a, double(i));
      for (int c = 0; c < 2; ++c) sum[c] += w * in(i, c);
    }
    for (int c = 0; c < 2; ++c) out(o, c, float(sum[c] / ratio));
  }
}
}  // namespace

NormalMapImage bc5RoundTripResized(const NormalMapImage& map, uint32_t width, uint32_t height) {
  const size_t texels = checkedTexels(map);
  if (width == 0 || height == 0 || width > map.width || height > map.height)
    throw Error("bc5 baseline: cannot resize a " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                " map to " + std::to_string(width) + "x" + std::to_string(height));
  // Rows first (map.height lines of map.width texels down to width), then the columns.
  std::vector<float> rows(size_t(width) * map.height * 2);
  for (uint32_t y = 0; y < map.height; ++y)
    boxDown(
        map.width, width, [&](uint32_t i, int c) { return map.xy[(size_t(y) * map.width + i) * 2 + c]; },
        [&](uint32_t o, int c, float v) { rows[(size_t(y) * width + o) * 2 + c] = v; });
  NormalMapImage small{width, height, std::vector<float>(size_t(width) * height * 2)};
  for (uint32_t x = 0; x < width; ++x)
    boxDown(
        map.height, height, [&](uint32_t i, int c) { return rows[(size_t(i) * width + x) * 2 + c]; },
        [&](uint32_t o, int c, float v) { small.xy[(size_t(o) * width + x) * 2 + c] = v; });
  const NormalMapImage decoded = bc5RoundTrip(small);
  // Bilinear back up, texel centres aligned, edges clamped (a sampler's linear filter, clamp to edge).
  NormalMapImage out{map.width, map.height, std::vector<float>(texels * 2)};
  auto coordinate = [](uint32_t i, uint32_t from, uint32_t to, uint32_t& i0, uint32_t& i1, float& f) {
    const double s = std::clamp((double(i) + 0.5) * double(to) / double(from) - 0.5, 0.0, double(to - 1));
    i0 = uint32_t(s);
    i1 = std::min(i0 + 1, to - 1);
    f = float(s - i0);
  };
  for (uint32_t y = 0; y < map.height; ++y) {
    uint32_t y0, y1;
    float fy;
    coordinate(y, map.height, height, y0, y1, fy);
    for (uint32_t x = 0; x < map.width; ++x) {
      uint32_t x0, x1;
      float fx;
      coordinate(x, map.width, width, x0, x1, fx);
      for (int c = 0; c < 2; ++c) {
        auto at = [&](uint32_t xx, uint32_t yy) { return decoded.xy[(size_t(yy) * width + xx) * 2 + c]; };
        const float top = at(x0, y0) * (1 - fx) + at(x1, y0) * fx, bottom = at(x0, y1) * (1 - fx) + at(x1, y1) * fx;
        out.xy[(size_t(y) * map.width + x) * 2 + c] = top * (1 - fy) + bottom * fy;
      }
    }
  }
  return out;
}

}  // namespace swish::bake
