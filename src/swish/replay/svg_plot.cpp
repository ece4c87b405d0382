#include "swish/replay/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace swish::replay {

namespace {

constexpr double kW = 720, kH = 360, kL = 70, kR = 160, kT = 36, kB = 48;
const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};

std::string num(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.4g", v);
  return s;
}
std::string esc(const std::string& t) {
  std::string o;
  for (char c : t) o += c == '<' ? std::string("&lt;") : c == '>' ? std::string("&gt;") : c == '&' ? std::string("&amp;") : std::string(1, c);
  return o;
}

struct Frame {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  double px(double x) const { return kL + (x - x0) / (x1 - x0) * (kW - kL - kR); }
  double py(double y) const { return kH - kB - (y - y0) / (y1 - y0) * (kH - kT - kB); }
};

Frame rangeOf(const std::vector<PlotSeries>& series) {
  Frame f{1e300, -1e300, 0, -1e300};
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      f.x0 = std::min(f.x0, s.x[i]);
      f.x1 = std::max(f.x1, s.x[i]);
      f.y0 = std::min(f.y0, s.y[i]);
      f.y1 = std::max(f.y1, s.y[i]);
    }
  if (f.x0 > f.x1) f = {0, 1, 0, 1};
  if (f.x1 <= f.x0) f.x1 = f.x0 + 1;
  if (f.y1 <= f.y0) f.y1 = f.y0 + (f.y0 == 0 ? 1 : std::abs(f.y0));
  f.y1 += (f.y1 - f.y0) * 0.05;
  return f;
}

void header(std::ostringstream& s, const PlotAxes& a, const Frame& f) {
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << kH << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << kW / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << esc(a.title) << "</text>\n"
    << "<line x1=\"" << kL << "\" y1=\"" << kH - kB << "\" x2=\"" << kW - kR << "\" y2=\"" << kH - kB << "\" stroke=\"black\"/>\n"
    << "<line x1=\"" << kL << "\" y1=\"" << kT << "\" x2=\"" << kL << "\" y2=\"" << kH - kB << "\" stroke=\"black\"/>\n";
  for (int i = 0; i <= 4; ++i) {
    const double x = f.x0 + (f.x1 - f.x0) * i / 4, y = f.y0 + (f.y1 - f.y0) * i / 4;
    s << "<text x=\"" << num(f.px(x)) << "\" y=\"" << kH - kB + 14 << "\" text-anchor=\"middle\">" << num(x) << "</text>\n"
      << "<text x=\"" << kL - 4 << "\" y=\"" << num(f.py(y) + 4) << "\" text-anchor=\"end\">" << num(y) << "</text>\n"
      << "<line x1=\"" << kL << "\" y1=\"" << num(f.py(y)) << "\" x2=\"" << kW - kR << "\" y2=\"" << num(f.py(y))
      << "\" stroke=\"#ddd\"/>\n";
  }
  s << "<text x=\"" << (kL + kW - kR) / 2 << "\" y=\"" << kH - 10 << "\" text-anchor=\"middle\">" << esc(a.xLabel) << "</text>\n"
    << "<text x=\"14\" y=\"" << kH / 2 << "\" text-anchor=\"middle\" transform=\"rotate(-90 14 " << kH / 2 << ")\">"
    << esc(a.yLabel) << "</text>\n";
}

void legend(std::ostringstream& s, const std::vector<PlotSeries>& series) {
  for (size_t i = 0; i < series.size(); ++i) {
    const double y = kT + 14 * double(i);
    s << "<rect x=\"" << kW - kR + 10 << "\" y=\"" << y << "\" width=\"10\" height=\"10\" fill=\"" << kColours[i % 8] << "\"/>\n"
      << "<text x=\"" << kW - kR + 24 << "\" y=\"" << y + 9 << "\">" << esc(series[i].name) << "</text>\n";
  }
}

}  // namespace

std::string svgLineChart(const PlotAxes& a, const std::vector<PlotSeries>& series) {
  const Frame f = rangeOf(series);
  std::ostringstream s;
  header(s, a, f);
  for (size_t i = 0; i < series.size(); ++i) {
    s << "<polyline fill=\"none\" stroke=\"" << kColours[i % 8] << "\" stroke-width=\"1.5\" points=\"";
    for (size_t p = 0; p < series[i].x.size() && p < series[i].y.size(); ++p)
      if (std::isfinite(series[i].x[p]) && std::isfinite(series[i].y[p]))
        s << num(f.px(series[i].x[p])) << "," << num(f.py(series[i].y[p])) << " ";
    s << "\"/>\n";
  }
  legend(s, series);
  s << "</svg>\n";
  return s.str();
}

std::string svgScatter(const PlotAxes& a, const std::vector<PlotSeries>& series) {
  const Frame f = rangeOf(series);
  std::ostringstream s;
  header(s, a, f);
  for (size_t i = 0; i < series.size(); ++i)
    for (size_t p = 0; p < series[i].x.size() && p < series[i].y.size(); ++p)
      if (std::isfinite(series[i].x[p]) && std::isfinite(series[i].y[p]))
        s << "<circle cx=\"" << num(f.px(series[i].x[p])) << "\" cy=\"" << num(f.py(series[i].y[p])) << "\" r=\"3\" fill=\""
          << kColours[i % 8] << "\" fill-opacity=\"0.7\"/>\n";
  legend(s, series);
  s << "</svg>\n";
  return s.str();
}

std::string svgBarChart(const PlotAxes& a, const std::vector<std::string>& labels, const std::vector<double>& values) {
  double top = 0;
  for (double v : values)
    if (std::isfinite(v)) top = std::max(top, v);
  if (top <= 0) top = 1;
  const double rowH = 22, h = kT + rowH * double(labels.size()) + 30, left = 200, right = 100;
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << h << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << kW / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << esc(a.title) << "</text>\n";
  for (size_t i = 0; i < labels.size(); ++i) {
    const double y = kT + rowH * double(i), v = i < values.size() && std::isfinite(values[i]) ? values[i] : 0.0;
    const double w = v / top * (kW - left - right);
    s << "<text x=\"" << left - 6 << "\" y=\"" << y + 14 << "\" text-anchor=\"end\">" << esc(labels[i]) << "</text>\n"
      << "<rect x=\"" << left << "\" y=\"" << y + 3 << "\" width=\"" << num(w) << "\" height=\"" << rowH - 6 << "\" fill=\""
      << kColours[i % 8] << "\"/>\n"
      << "<text x=\"" << num(left + w + 4) << "\" y=\"" << y + 14 << "\">" << num(v) << " " << esc(a.xLabel) << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace swish::replay
