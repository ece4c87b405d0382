#include "swish/runtime/temporal_filter.hpp"

#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

TemporalFilter::TemporalFilter(float timeConstantSeconds) : timeConstant_(timeConstantSeconds) {
  if (!(timeConstantSeconds >= 0.f) || !std::isfinite(timeConstantSeconds))
    throw Error("temporal filter: time constant " + std::to_string(timeConstantSeconds) + " s must be finite and >= 0");
}

float TemporalFilter::alphaFor(float dt, float timeConstant, bool* invalidDt) {
  const bool invalid = !(dt >= 0.f);  // negative or NaN
  if (invalidDt) *invalidDt = invalid;
  if (invalid || dt == 0.f) return 0.f;
  if (!(timeConstant > 0.f)) return 1.f;
  // In double: dt / timeConstant may overflow float (tiny time constant), and expm1 keeps the small-dt
  // end accurate. exp(-x) for x > ~104 is below float's smallest subnormal: alpha is exactly 1.
  const double x = double(dt) / double(timeConstant);
  const float alpha = float(-std::expm1(-x));
  return alpha > 1.f ? 1.f : alpha;
}

BlendStep TemporalFilter::step(float dtSeconds, uint32_t selectedMap) {
  BlendStep s;
  s.selectedMap = selectedMap;
  s.alpha = alphaFor(dtSeconds, timeConstant_, &s.invalidDt);
  if (!hasHistory_) {
    s.alpha = 1.f;
    s.firstFrame = true;
    hasHistory_ = true;
  }
  return s;
}

}  // namespace swish::runtime
