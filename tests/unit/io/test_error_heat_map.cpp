// io/error_heat_map: the colour scale, its round tops, and the figure (model | truth | heat map with a
// legend): panels framed alike, error colours where the error is.
#include <gtest/gtest.h>

#include "swish/core/error.hpp"
#include "swish/io/error_heat_map.hpp"

namespace swish {
namespace {

TEST(ErrorHeatMap, ColourScaleAndRoundTops) {
  EXPECT_EQ(io::heatColour(0, 10), (std::array<uint8_t, 3>{20, 30, 140}));
  EXPECT_EQ(io::heatColour(10, 10), (std::array<uint8_t, 3>{220, 20, 20}));
  EXPECT_EQ(io::heatColour(25, 10), io::heatColour(10, 10)) << "beyond the scale: its top colour";
  EXPECT_EQ(io::heatColour(5, 10), (std::array<uint8_t, 3>{40, 190, 60}));
  EXPECT_DOUBLE_EQ(io::heatScaleMm(0.3), 1);
  EXPECT_DOUBLE_EQ(io::heatScaleMm(3.2), 5);
  EXPECT_DOUBLE_EQ(io::heatScaleMm(7), 10);
  EXPECT_DOUBLE_EQ(io::heatScaleMm(11), 20);
}

// Two triangles forming a square; the model's right half is 8 mm off the truth, its left on it.
TEST(ErrorHeatMap, FigureShowsTheErrorWhereItIs) {
  Points3f truth(4, 3);
  truth << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Triangles tris(2, 3);
  tris << 0, 1, 2, 0, 2, 3;
  Points3f model = truth;
  model(1, 2) += 0.008f, model(2, 2) += 0.008f;
  io::HeatMapFigure f;
  f.title = "Pose 7";
  f.model = &model, f.truth = &truth, f.triangles = &tris;
  f.panelWidth = 100, f.panelHeight = 100;
  f.scaleMm = 10;
  std::vector<double> err;
  const io::PngImage png = io::heatMapFigure(f, &err);
  ASSERT_EQ(err.size(), 4u);
  EXPECT_NEAR(err[1], 8.0, 1e-3);
  EXPECT_NEAR(err[0], 0.0, 1e-6);
  EXPECT_EQ(png.channels, 3u);
  EXPECT_EQ(png.width, 3u * 100 + 90);
  // In the heat panel (the third), the lower-right triangle (vertices 0, 1, 2: errors 0, 8, 8) is warmer
  // than the upper-left one (0, 8, 0): red minus blue, sampled inside each.
  auto px = [&](int x, int y) {
    return std::array<int, 3>{png.at(uint32_t(x), uint32_t(y), 0), png.at(uint32_t(x), uint32_t(y), 1),
                              png.at(uint32_t(x), uint32_t(y), 2)};
  };
  const int top = 24;
  const auto lowerRight = px(200 + 75, top + 70), upperLeft = px(200 + 25, top + 30);
  EXPECT_GT(lowerRight[0] - lowerRight[2], upperLeft[0] - upperLeft[2]);
  // The truth panel is plain grey (r = g = b, shaded).
  const auto plain = px(100 + 50, top + 50);
  EXPECT_EQ(plain[0], plain[1]);
  EXPECT_NE(plain, (std::array<int, 3>{240, 241, 245})) << "the mesh covers the panel's centre";
  Points3f wrong(3, 3);
  wrong.setZero();
  f.truth = &wrong;
  EXPECT_THROW(io::heatMapFigure(f), Error);
}

}  // namespace
}  // namespace swish
