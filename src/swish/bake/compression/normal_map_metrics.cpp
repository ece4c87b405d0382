#include "swish/bake/compression/normal_map_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace {
constexpr double kBinDegrees = 0.01;
constexpr size_t kBins = size_t(180.0 / kBinDegrees) + 1;

void unitNormal(float x, float y, double out[3]) {
  const double xx = x, yy = y, zz2 = 1.0 - xx * xx - yy * yy;
  double v[3] = {xx, yy, zz2 > 0.0 ? std::sqrt(zz2) : 0.0};
  const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int i = 0; i < 3; ++i) out[i] = len > 0.0 ? v[i] / len : (i == 2 ? 1.0 : 0.0);
}
}  // namespace

double texelAngleDegrees(float x0, float y0, float x1, float y1) {
  double a[3], b[3];
  unitNormal(x0, y0, a);
  unitNormal(x1, y1, b);
  // atan2 of |a x b| and a.b stays accurate for tiny angles, where acos(a.b) does not.
  const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  const double s = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  return std::atan2(s, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * 180.0 / M_PI;
}

AngularErrorAccumulator::AngularErrorAccumulator() : bins_(kBins, 0) {}

void AngularErrorAccumulator::add(double degrees) {
  if (!std::isfinite(degrees)) degrees = 180.0;
  degrees = std::clamp(degrees, 0.0, 180.0);
  ++bins_[std::min(kBins - 1, size_t(degrees / kBinDegrees))];
  sum_ += degrees;
  max_ = std::max(max_, degrees);
  ++count_;
}

void AngularErrorAccumulator::addMaps(const NormalMapImage& truth, const NormalMapImage& approx) {
  if (truth.width != approx.width || truth.height != approx.height || truth.xy.size() != approx.xy.size() ||
      truth.xy.size() != size_t(truth.width) * truth.height * 2)
    throw Error("normal-map error: maps differ in size (" + std::to_string(truth.width) + "x" +
                std::to_string(truth.height) + " vs " + std::to_string(approx.width) + "x" +
                std::to_string(approx.height) + ")");
  for (size_t i = 0; i < truth.xy.size(); i += 2)
    add(texelAngleDegrees(truth.xy[i], truth.xy[i + 1], approx.xy[i], approx.xy[i + 1]));
}

void AngularErrorAccumulator::merge(const AngularErrorAccumulator& o) {
  for (size_t i = 0; i < kBins; ++i) bins_[i] += o.bins_[i];
  sum_ += o.sum_;
  max_ = std::max(max_, o.max_);
  count_ += o.count_;
}

AngularErrorStats AngularErrorAccumulator::stats() const {
  AngularErrorStats s;
  s.texels = count_;
  if (count_ == 0) return s;
  s.meanDegrees = sum_ / double(count_);
  s.maxDegrees = max_;
  const uint64_t target = uint64_t(std::ceil(0.95 * double(count_)));
  uint64_t seen = 0;
  for (size_t i = 0; i < kBins; ++i) {
    seen += bins_[i];
    if (seen >= target) {
      s.p95Degrees = std::min(max_, (double(i) + 1.0) * kBinDegrees);  // upper edge of the bin
      break;
    }
  }
  return s;
}

AngularErrorStats angularError(const NormalMapImage& truth, const NormalMapImage& approx) {
  AngularErrorAccumulator acc;
  acc.addMaps(truth, approx);
  return acc.stats();
}

}  // namespace swish::bake
