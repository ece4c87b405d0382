#include "swish/io/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace swish::io {

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

namespace {
const char* const kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};
constexpr size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Ticks at 1, 2 or 5 x 10^k spacing, about `count` of them.
std::vector<double> niceTicks(double lo, double hi, int count) {
  std::vector<double> t;
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / count, mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = mag * (raw / mag < 1.5 ? 1 : raw / mag < 3.5 ? 2 : raw / mag < 7.5 ? 5 : 10);
  for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-9; v += step)
    t.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  return t;
}
}  // namespace

std::string SvgPlot::render() const {
  const double left = 70, right = 20, top = 36, bottom = 50;
  const double pw = width - left - right, ph = height - top - bottom;
  auto ty = [&](double y) { return logY ? std::log10(y) : y; };
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (logY && s.y[i] <= 0)) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, ty(s.y[i])), y1 = std::max(y1, ty(s.y[i]));
    }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 == x0) x0 -= 0.5, x1 += 0.5;
  if (!logY && yFromZero && y0 > 0) y0 = 0;  // before widening a flat range, so that it still starts at 0
  if (y1 == y0) y0 -= 0.5, y1 += 0.5;
  if (!logY && y0 > 0 && y0 < 0.5 * y1) y0 = 0;  // anchor linear error plots at zero
  const double padY = (y1 - y0) * 0.05;
  y0 -= logY ? 0 : padY, y1 += padY;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return top + (1.0 - (ty(y) - y0) / (y1 - y0)) * ph; };

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << width / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << xmlEscape(title)
    << "</text>\n";
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"#444\"/>\n";
  for (double t : niceTicks(x0, x1, 6)) {
    o << "<line x1=\"" << px(t) << "\" y1=\"" << top + ph << "\" x2=\"" << px(t) << "\" y2=\"" << top + ph + 5
      << "\" stroke=\"#444\"/><text x=\"" << px(t) << "\" y=\"" << top + ph + 18 << "\" text-anchor=\"middle\">"
      << fmt(t) << "</text>\n";
  }
  std::vector<double> yt;
  if (logY)
    for (double e = std::ceil(y0); e <= std::floor(y1); ++e) yt.push_back(std::pow(10.0, e));
  else
    yt = niceTicks(y0, y1, 5);
  for (double t : yt) {
    o << "<line x1=\"" << left - 5 << "\" y1=\"" << py(t) << "\" x2=\"" << left + pw << "\" y2=\"" << py(t)
      << "\" stroke=\"#ddd\"/><text x=\"" << left - 8 << "\" y=\"" << py(t) + 4 << "\" text-anchor=\"end\">" << fmt(t)
      << "</text>\n";
  }
  o << "<text x=\"" << left + pw / 2 << "\" y=\"" << height - 10 << "\" text-anchor=\"middle\">" << xmlEscape(xLabel)
    << "</text>\n<text transform=\"translate(16," << top + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << xmlEscape(yLabel) << (logY ? " (log)" : "") << "</text>\n";
  for (size_t si = 0; si < series.size(); ++si) {
    const auto& s = series[si];
    const std::string colour = s.colour.empty() ? kPalette[si % kPaletteSize] : s.colour;
    if (!s.markers) o << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\" points=\"";
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (logY && s.y[i] <= 0)) continue;
      if (s.markers)
        o << "<circle cx=\"" << px(s.x[i]) << "\" cy=\"" << py(s.y[i]) << "\" r=\"3\" fill=\"" << colour
          << "\" fill-opacity=\"0.7\"/>\n";
      else
        o << px(s.x[i]) << "," << py(s.y[i]) << " ";
    }
    if (!s.markers) o << "\"/>\n";
    o << "<rect x=\"" << left + pw - 170 << "\" y=\"" << top + 10 + 18 * si << "\" width=\"12\" height=\"3\" fill=\""
      << colour << "\"/><text x=\"" << left + pw - 152 << "\" y=\"" << top + 15 + 18 * si << "\">" << xmlEscape(s.label)
      << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string SvgBarChart::render() const {
  double top = 0;
  for (double v : values)
    if (std::isfinite(v)) top = std::max(top, v);
  if (top <= 0) top = 1;
  const double rowH = 22, rowsTop = 36, left = 200, right = 100;
  const double height = rowsTop + rowH * double(labels.size()) + 30;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << width / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << xmlEscape(title)
    << "</text>\n";
  for (size_t i = 0; i < labels.size(); ++i) {
    const double y = rowsTop + rowH * double(i), v = i < values.size() && std::isfinite(values[i]) ? values[i] : 0.0;
    const double w = v / top * (width - left - right);
    o << "<text x=\"" << left - 6 << "\" y=\"" << y + 14 << "\" text-anchor=\"end\">" << xmlEscape(labels[i])
      << "</text>\n"
      << "<rect x=\"" << left << "\" y=\"" << y + 3 << "\" width=\"" << w << "\" height=\"" << rowH - 6 << "\" fill=\""
      << kPalette[i % kPaletteSize] << "\"/>\n"
      << "<text x=\"" << left + w + 4 << "\" y=\"" << y + 14 << "\">" << fmt(v) << (unit.empty() ? "" : " ")
      << xmlEscape(unit) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace swish::io
