#include "swish/io/error_heat_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "swish/core/error.hpp"

namespace swish::io {

namespace {

// 5x7 glyphs, one row per string, '#' set.
const std::map<char, std::array<const char*, 7>>& font() {
  static const std::map<char, std::array<const char*, 7>> f = {
      {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
      {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
      {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
      {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
      {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
      {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
      {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
      {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
      {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
      {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
      {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
      {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
      {':', {"     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     "}},
      {',', {"     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   "}},
      {'(', {"   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # "}},
      {')', {" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   "}},
      {'+', {"     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     "}},
      {'_', {"     ", "     ", "     ", "     ", "     ", "     ", "#####"}},
      {'/', {"    #", "    #", "   # ", "  #  ", " #   ", "#    ", "#    "}},
      {'b', {"#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#### "}},
      {'c', {"     ", "     ", " ### ", "#    ", "#    ", "#   #", " ### "}},
      {'j', {"   # ", "     ", "  ## ", "   # ", "   # ", "#  # ", " ##  "}},
      {'k', {"#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # "}},
      {'q', {"     ", "     ", " ## #", "#  ##", " ####", "    #", "    #"}},
      {'w', {"     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # "}},
      {'z', {"     ", "     ", "#####", "   # ", "  #  ", " #   ", "#####"}},
      {'a', {"     ", "     ", " ### ", "    #", " ####", "#   #", " ####"}},
      {'d', {"    #", "    #", " ## #", "#  ##", "#   #", "#   #", " ####"}},
      {'e', {"     ", "     ", " ### ", "#   #", "#####", "#    ", " ### "}},
      {'f', {"  ## ", " #  #", " #   ", "###  ", " #   ", " #   ", " #   "}},
      {'g', {"     ", " ####", "#   #", "#   #", " ####", "    #", " ### "}},
      {'h', {"#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#   #"}},
      {'i', {"  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### "}},
      {'l', {" ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
      {'m', {"     ", "     ", "## # ", "# # #", "# # #", "#   #", "#   #"}},
      {'n', {"     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #"}},
      {'o', {"     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### "}},
      {'p', {"     ", "     ", "#### ", "#   #", "#### ", "#    ", "#    "}},
      {'r', {"     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    "}},
      {'s', {"     ", "     ", " ####", "#    ", " ### ", "    #", "#### "}},
      {'t', {" #   ", " #   ", "###  ", " #   ", " #   ", " #  #", "  ## "}},
      {'u', {"     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #"}},
      {'v', {"     ", "     ", "#   #", "#   #", "#   #", " # # ", "  #  "}},
      {'x', {"     ", "     ", "#   #", " # # ", "  #  ", " # # ", "#   #"}},
      {'y', {"     ", "     ", "#   #", "#   #", " ####", "    #", " ### "}},
  };
  return f;
}

std::array<uint8_t, 3> shade(std::array<uint8_t, 3> c, float k) {
  return {uint8_t(std::clamp(float(c[0]) * k, 0.f, 255.f)), uint8_t(std::clamp(float(c[1]) * k, 0.f, 255.f)),
          uint8_t(std::clamp(float(c[2]) * k, 0.f, 255.f))};
}

std::string mmText(double v) {
  char s[32];
  std::snprintf(s, sizeof s, v < 10 && v != std::floor(v) ? "%.1f" : "%.0f", v);
  return s;
}

}  // namespace

RgbCanvas::RgbCanvas(uint32_t w, uint32_t h, std::array<uint8_t, 3> fill)
    : width(w), height(h), rgb(size_t(w) * h * 3) {
  for (size_t p = 0; p < size_t(w) * h; ++p) std::copy(fill.begin(), fill.end(), rgb.begin() + long(p * 3));
}

void RgbCanvas::set(int x, int y, std::array<uint8_t, 3> c) {
  if (x < 0 || y < 0 || x >= int(width) || y >= int(height)) return;
  std::copy(c.begin(), c.end(), rgb.begin() + long((size_t(y) * width + size_t(x)) * 3));
}

PngImage RgbCanvas::png() const {
  PngImage p;
  p.width = width, p.height = height, p.channels = 3, p.bitDepth = 8;
  p.samples.assign(rgb.begin(), rgb.end());
  return p;
}

std::array<uint8_t, 3> heatColour(double mm, double scaleMm) {
  // Stops: dark blue, cyan, green, yellow, red.
  static const float stops[5][3] = {{20, 30, 140}, {0, 190, 220}, {40, 190, 60}, {250, 220, 0}, {220, 20, 20}};
  double t = scaleMm > 0 && std::isfinite(mm) ? std::clamp(mm / scaleMm, 0.0, 1.0) : 1.0;
  const double f = t * 4.0;
  const int i = std::min(3, int(f));
  const double u = f - i;
  std::array<uint8_t, 3> c;
  for (int a = 0; a < 3; ++a) c[a] = uint8_t(std::lround(stops[i][a] * (1 - u) + stops[i + 1][a] * u));
  return c;
}

double heatScaleMm(double p99) {
  for (double decade = 1; decade < 1e6; decade *= 10)
    for (double m : {1.0, 2.0, 5.0})
      if (m * decade >= p99) return m * decade;
  return 1e6;
}

int drawText(RgbCanvas& c, int x, int y, const std::string& text, std::array<uint8_t, 3> colour, int scale) {
  int cx = x;
  for (char ch : text) {
    if (ch >= 'A' && ch <= 'Z') ch = char(ch - 'A' + 'a');  // one case is enough for captions
    const auto it = font().find(ch);
    if (it != font().end())
      for (int r = 0; r < 7; ++r)
        for (int k = 0; k < 5; ++k)
          if (it->second[size_t(r)][k] == '#')
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx) c.set(cx + k * scale + sx, y + r * scale + sy, colour);
    cx += 6 * scale;
  }
  return cx - x;
}

void rasterizeMesh(RgbCanvas& canvas, int x0, int y0, int w, int h, const Points3f& pos, const Triangles& tris,
                   const std::vector<std::array<uint8_t, 3>>& colours, const Vec3f& lo, const Vec3f& hi) {
  const float bw = std::max(1e-6f, hi.x() - lo.x()), bh = std::max(1e-6f, hi.y() - lo.y());
  const float scale = 0.92f * std::min(float(w) / bw, float(h) / bh);
  const float cx = 0.5f * (lo.x() + hi.x()), cy = 0.5f * (lo.y() + hi.y());
  auto toPixel = [&](const Vec3f& p) {
    return Vec3f(float(x0) + 0.5f * float(w) + (p.x() - cx) * scale, float(y0) + 0.5f * float(h) - (p.y() - cy) * scale,
                 p.z());
  };
  std::vector<float> depth(size_t(w) * size_t(h), -std::numeric_limits<float>::infinity());
  const Vec3f light = Vec3f(0.35f, 0.5f, 0.8f).normalized();
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const Vec3f a = pos.row(tris(t, 0)).transpose(), b = pos.row(tris(t, 1)).transpose(),
                c = pos.row(tris(t, 2)).transpose();
    if (!a.allFinite() || !b.allFinite() || !c.allFinite()) continue;
    Vec3f n = (b - a).cross(c - a);
    if (n.norm() == 0.f) continue;
    n.normalize();
    const float k = 0.35f + 0.65f * std::abs(n.dot(light));  // two-sided: the inside of a sleeve is lit too
    std::array<int, 3> col{0, 0, 0};
    for (int v = 0; v < 3; ++v)
      for (int ch = 0; ch < 3; ++ch) col[size_t(ch)] += colours[tris(t, v)][size_t(ch)];
    const std::array<uint8_t, 3> face = shade({uint8_t(col[0] / 3), uint8_t(col[1] / 3), uint8_t(col[2] / 3)}, k);
    const Vec3f pa = toPixel(a), pb = toPixel(b), pc = toPixel(c);
    const int xmin = std::max(x0, int(std::floor(std::min({pa.x(), pb.x(), pc.x()})))),
              xmax = std::min(x0 + w - 1, int(std::ceil(std::max({pa.x(), pb.x(), pc.x()}))));
    const int ymin = std::max(y0, int(std::floor(std::min({pa.y(), pb.y(), pc.y()})))),
              ymax = std::min(y0 + h - 1, int(std::ceil(std::max({pa.y(), pb.y(), pc.y()}))));
    const float area = (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pb.y() - pa.y()) * (pc.x() - pa.x());
    if (std::abs(area) < 1e-12f) continue;
    for (int y = ymin; y <= ymax; ++y)
      for (int x = xmin; x <= xmax; ++x) {
        const float px = float(x) + 0.5f, py = float(y) + 0.5f;
        const float w0 = ((pb.x() - px) * (pc.y() - py) - (pb.y() - py) * (pc.x() - px)) / area;
        const float w1 = ((pc.x() - px) * (pa.y() - py) - (pc.y() - py) * (pa.x() - px)) / area;
        const float w2 = 1.f - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const float z = w0 * pa.z() + w1 * pb.z() + w2 * pc.z();
        float& d = depth[size_t(y - y0) * size_t(w) + size_t(x - x0)];
        if (z <= d) continue;
        d = z;
        canvas.set(x, y, face);
      }
  }
}

PngImage heatMapFigure(const HeatMapFigure& f, std::vector<double>* errorsOut) {
  if (!f.model || !f.truth || !f.triangles) throw Error("heat map: model, truth and triangles are required");
  const Points3f& m = *f.model;
  const Points3f& t = *f.truth;
  if (m.rows() != t.rows())
    throw Error("heat map: the model has " + std::to_string(m.rows()) + " vertices, the truth " +
                std::to_string(t.rows()));
  std::vector<double> err(size_t(m.rows()));
  for (Eigen::Index v = 0; v < m.rows(); ++v) err[size_t(v)] = 1000.0 * double((m.row(v) - t.row(v)).norm());
  double scale = f.scaleMm;
  if (!(scale > 0)) {
    std::vector<double> s = err;
    std::sort(s.begin(), s.end());
    scale = heatScaleMm(s.empty() ? 1.0 : s[std::min(s.size() - 1, size_t(0.99 * double(s.size())))]);
  }
  // One framing for all three panels: the union of both meshes' bounds.
  Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  for (const Points3f* p : {&m, &t})
    for (Eigen::Index v = 0; v < p->rows(); ++v)
      if (p->row(v).allFinite()) lo = lo.cwiseMin(p->row(v).transpose()), hi = hi.cwiseMax(p->row(v).transpose());
  if (!lo.allFinite()) lo = Vec3f::Zero(), hi = Vec3f::Ones();
  const int pw = int(f.panelWidth), ph = int(f.panelHeight), top = 24, caption = 18, legendW = 90;
  RgbCanvas c(uint32_t(3 * pw + legendW), uint32_t(top + ph + caption), {240, 241, 245});
  const std::array<uint8_t, 3> ink{30, 30, 40}, plain{200, 200, 205};
  drawText(c, 6, 6, f.title, ink, 2);
  const std::vector<std::array<uint8_t, 3>> grey(size_t(m.rows()), plain);
  std::vector<std::array<uint8_t, 3>> heat(size_t(m.rows()));
  for (size_t v = 0; v < err.size(); ++v) heat[v] = heatColour(err[v], scale);
  rasterizeMesh(c, 0, top, pw, ph, m, *f.triangles, grey, lo, hi);
  rasterizeMesh(c, pw, top, pw, ph, t, *f.triangles, grey, lo, hi);
  rasterizeMesh(c, 2 * pw, top, pw, ph, m, *f.triangles, heat, lo, hi);
  drawText(c, pw / 2 - 15, top + ph + 4, "model", ink);
  drawText(c, pw + pw / 2 - 15, top + ph + 4, "truth", ink);
  drawText(c, 2 * pw + pw / 2 - 40, top + ph + 4, "error (mm)", ink);
  // Legend: a vertical bar, full scale at the top, with 0, half and full scale labelled.
  const int bx = 3 * pw + 12, by = top + 20, bh = ph - 60;
  for (int y = 0; y < bh; ++y) {
    const auto col = heatColour(scale * double(bh - 1 - y) / double(bh - 1), scale);
    for (int x = 0; x < 16; ++x) c.set(bx + x, by + y, col);
  }
  drawText(c, bx, top + 4, "mm", ink);
  drawText(c, bx + 22, by - 3, mmText(scale) + "+", ink);
  drawText(c, bx + 22, by + bh / 2 - 3, mmText(scale / 2), ink);
  drawText(c, bx + 22, by + bh - 7, "0", ink);
  if (errorsOut) *errorsOut = std::move(err);
  return c.png();
}

}  // namespace swish::io
