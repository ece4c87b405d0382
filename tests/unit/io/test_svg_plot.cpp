// SVG plots (io/svg_plot), used by the bake and the replay reports: titles, axis labels and legend
// entries are written and escaped, lines and scatter dots get one mark per finite point, a linear y
// axis reaches 0 when asked, and bar charts carry one labelled bar per value with its unit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "swish/io/svg_plot.hpp"

using namespace swish::io;

namespace {

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + what.size())) ++n;
  return n;
}

TEST(SvgPlot, LinesHaveTitleAxesAndLegend) {
  SvgPlot p;
  p.title = "Time <per> frame", p.xLabel = "scene frame", p.yLabel = "ms";
  p.series.push_back({"CPU & GPU", {0, 1, 2}, {1, NAN, 3}, ""});
  p.series.push_back({"wait", {0, 1, 2}, {2, 2, 2}, "#123456"});
  const std::string svg = p.render();
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("Time &lt;per&gt; frame"), std::string::npos);
  EXPECT_NE(svg.find(">scene frame<"), std::string::npos);
  EXPECT_NE(svg.find(">ms<"), std::string::npos);
  EXPECT_NE(svg.find(">CPU &amp; GPU<"), std::string::npos);
  EXPECT_NE(svg.find(">wait<"), std::string::npos);
  EXPECT_EQ(count(svg, "<polyline"), 2u);
  EXPECT_NE(svg.find("stroke=\"#123456\""), std::string::npos);
  EXPECT_EQ(count(svg, "<circle"), 0u);
}

TEST(SvgPlot, MarkersDrawOneDotPerFinitePoint) {
  SvgPlot p;
  p.series.push_back({"checked frames", {1, 2, 3, 4}, {0.5, 0.25, NAN, 1.0}, ""});
  p.series.back().markers = true;
  const std::string svg = p.render();
  EXPECT_EQ(count(svg, "<circle"), 3u);
  EXPECT_EQ(count(svg, "<polyline"), 0u);
  EXPECT_NE(svg.find(">checked frames<"), std::string::npos);
}

TEST(SvgPlot, YFromZeroPutsATickAtZero) {
  SvgPlot p;
  p.series.push_back({"s", {0, 1}, {10, 11}, ""});
  EXPECT_EQ(p.render().find("text-anchor=\"end\">0</text>"), std::string::npos);  // 10..11: no zero
  p.yFromZero = true;
  EXPECT_NE(p.render().find("text-anchor=\"end\">0</text>"), std::string::npos);
}

TEST(SvgBarChart, OneBarPerValueWithItsUnit) {
  SvgBarChart b;
  b.title = "Median time per stage", b.unit = "ms";
  b.labels = {"CPU MLP", "GPU <deform>", "missing"};
  b.values = {2.0, 0.5, NAN};
  const std::string svg = b.render();
  EXPECT_NE(svg.find(">Median time per stage<"), std::string::npos);
  EXPECT_NE(svg.find(">CPU MLP<"), std::string::npos);
  EXPECT_NE(svg.find(">GPU &lt;deform&gt;<"), std::string::npos);
  EXPECT_NE(svg.find(">2 ms<"), std::string::npos);
  EXPECT_NE(svg.find(">0.5 ms<"), std::string::npos);
  EXPECT_NE(svg.find(">0 ms<"), std::string::npos);  // non-finite drawn as 0
  EXPECT_EQ(count(svg, "<rect x="), 3u);
}

}  // namespace
