#pragma once
// Minimal SVG charts for replay reports: line charts (several series over a shared x), scatter plots
// and horizontal bar charts. Deterministic text output (fixed number formatting), viewable in any
// browser and in Markdown previews.
#include <string>
#include <vector>

namespace swish::replay {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // NaN points are skipped
};

struct PlotAxes {
  std::string title, xLabel, yLabel;
};

std::string svgLineChart(const PlotAxes& axes, const std::vector<PlotSeries>& series);
std::string svgScatter(const PlotAxes& axes, const std::vector<PlotSeries>& series);
std::string svgBarChart(const PlotAxes& axes, const std::vector<std::string>& labels, const std::vector<double>& values);

}  // namespace swish::replay
