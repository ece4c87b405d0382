#pragma once
// A small SVG line-plot writer for the bake report (error against K, training curves): axes with
// "nice" ticks, optional log-scaled y, several labelled series, a legend. Self-contained SVG text.
#include <string>
#include <vector>

namespace swish::bake {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // same length; non-finite points (and <= 0 on a log axis) are skipped
  std::string colour;        // CSS colour; empty: from a fixed palette
};

struct SvgPlot {
  std::string title, xLabel, yLabel;
  bool logY = false;
  int width = 640, height = 400;
  std::vector<PlotSeries> series;

  std::string render() const;
};

// Escapes &, <, > and quotes for SVG/XML text.
std::string xmlEscape(const std::string& s);

}  // namespace swish::bake
