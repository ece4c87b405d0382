#pragma once
// A small SVG plot writer for the bake and replay reports (error against K, training curves, time and
// error per frame): line or scatter plots with "nice" ticks, optional log-scaled y, several labelled
// series and a legend; and horizontal bar charts. Self-contained SVG text.
#include <string>
#include <vector>

namespace swish::io {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // same length; non-finite points (and <= 0 on a log axis) are skipped
  std::string colour;        // CSS colour; empty: from a fixed palette
  bool markers = false;      // a dot per point instead of a line through them (a scatter plot)
};

struct SvgPlot {
  std::string title, xLabel, yLabel;
  bool logY = false;
  bool yFromZero = false;  // linear y: the axis always reaches down to 0 (otherwise only when close)
  int width = 640, height = 400;
  std::vector<PlotSeries> series;

  std::string render() const;
};

// Horizontal bars, one labelled row per value, scaled to the largest value; each bar is followed by
// its value and `unit`. Non-finite values are drawn as 0. The height follows the number of rows.
struct SvgBarChart {
  std::string title, unit;
  std::vector<std::string> labels;
  std::vector<double> values;  // values[i] belongs to labels[i]
  int width = 720;

  std::string render() const;
};

// Escapes &, <, > and quotes for SVG/XML text.
std::string xmlEscape(const std::string& s);

}  // namespace swish::io
