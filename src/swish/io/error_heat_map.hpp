#pragma once
// Error you can look at: a garment drawn beside its ground truth and as a per-vertex error heat map
// with a colour scale in millimetres and its legend, as one RGB PNG. Used by `swish replay
// --truth-every N --render` (frames with truth) and by the bake report's worst-pose gallery.
//
// Drawn by a small software rasteriser (z-buffered triangles, flat Lambert shading, a fixed front view
// framing both meshes alike), not by the Vulkan preview: the bake has no device, the figure must look
// the same wherever it is made, and three panels of a few thousand triangles take milliseconds.
// Labels use a built-in 5x7 pixel font (digits and the few letters the captions need).
#include <array>
#include <string>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/io/png.hpp"

namespace swish::io {

struct RgbCanvas {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;  // row-major from the top, 3 per pixel
  RgbCanvas(uint32_t w, uint32_t h, std::array<uint8_t, 3> fill);
  void set(int x, int y, std::array<uint8_t, 3> c);
  PngImage png() const;
};

// The colour of an error of `mm` on a scale from 0 (dark blue) through cyan, green and yellow to red at
// `scaleMm` and beyond. sRGB 8-bit.
std::array<uint8_t, 3> heatColour(double mm, double scaleMm);
// A round scale top for errors whose 99th percentile is `p99Mm`: the smallest of 1, 2, 5, 10, 20, 50,
// ... mm at or above it.
double heatScaleMm(double p99Mm);

// Text in the built-in font at (x, y) = top-left, `scale` pixels per font pixel. Characters it lacks
// are drawn as blanks. Returns the width drawn.
int drawText(RgbCanvas& canvas, int x, int y, const std::string& text, std::array<uint8_t, 3> colour, int scale = 1);

// Flat-shaded triangles, per-vertex colours averaged per face, seen from +Z looking down -Z,
// orthographic, framing the box [lo, hi] (x, y) inside the panel at (x0, y0) of size w x h.
void rasterizeMesh(RgbCanvas& canvas, int x0, int y0, int w, int h, const Points3f& positions,
                   const Triangles& triangles, const std::vector<std::array<uint8_t, 3>>& vertexColours,
                   const Vec3f& lo, const Vec3f& hi);

struct HeatMapFigure {
  std::string title;  // drawn above the panels
  const Points3f* model = nullptr;
  const Points3f* truth = nullptr;
  const Triangles* triangles = nullptr;
  uint32_t panelWidth = 300, panelHeight = 360;
  double scaleMm = 0;  // 0: heatScaleMm of the errors' 99th percentile
};

// Three panels: the model, the truth (both shaded plain), the model coloured by each vertex's distance
// to the truth; then the legend (colour bar, 0 / half / full scale in mm). Returns the image; the
// per-vertex errors (mm) in `errorsMm` when not null. Throws Error if the meshes' sizes differ.
PngImage heatMapFigure(const HeatMapFigure& figure, std::vector<double>* errorsMm = nullptr);

}  // namespace swish::io
