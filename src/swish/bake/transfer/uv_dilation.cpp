#include "swish/bake/transfer/uv_dilation.hpp"

#include "swish/core/error.hpp"

namespace swish::bake {

DilationResult dilateNormalMap(NormalMapImage& im, std::vector<uint8_t>& filled, int rings) {
  const size_t n = size_t(im.width) * im.height;
  if (filled.size() != n || im.xy.size() != 2 * n)
    throw Error("UV dilation: image " + std::to_string(im.width) + "x" + std::to_string(im.height) + " with " +
                std::to_string(im.xy.size()) + " floats and " + std::to_string(filled.size()) + " flags");
  DilationResult r;
  const int w = int(im.width), h = int(im.height);
  std::vector<uint32_t> frontier;
  for (int ring = 0; ring < rings; ++ring) {
    frontier.clear();
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (filled[size_t(y) * w + x]) continue;
        bool any = false;
        for (int dy = -1; dy <= 1 && !any; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < w && yy < h && filled[size_t(yy) * w + xx]) {
              any = true;
              break;
            }
          }
        if (any) frontier.push_back(uint32_t(y * w + x));
      }
    if (frontier.empty()) break;
    // Compute every new value from the previous ring's state, then mark them all.
    std::vector<float> values(2 * frontier.size());
    for (size_t i = 0; i < frontier.size(); ++i) {
      const int x = int(frontier[i] % uint32_t(w)), y = int(frontier[i] / uint32_t(w));
      float sx = 0.f, sy = 0.f;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const size_t t = size_t(yy) * w + xx;
          if (!filled[t]) continue;
          sx += im.xy[2 * t];
          sy += im.xy[2 * t + 1];
          ++count;
        }
      values[2 * i] = sx / float(count);
      values[2 * i + 1] = sy / float(count);
    }
    for (size_t i = 0; i < frontier.size(); ++i) {
      im.xy[2 * size_t(frontier[i])] = values[2 * i];
      im.xy[2 * size_t(frontier[i]) + 1] = values[2 * i + 1];
      filled[frontier[i]] = 1;
    }
    r.dilated += frontier.size();
  }
  for (size_t t = 0; t < n; ++t)
    if (!filled[t]) {
      im.xy[2 * t] = im.xy[2 * t + 1] = 0.f;
      filled[t] = 1;
      ++r.setToFlat;
    }
  return r;
}

}  // namespace swish::bake
