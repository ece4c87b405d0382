#include "swish/runtime/blended_map_weights.hpp"

#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

void BlendedMapWeights::apply(const BlendStep& step) {
  if (step.selectedMap >= weights_.size())
    throw Error("blended map weights: selected map " + std::to_string(step.selectedMap) + " outside a database of " +
                std::to_string(weights_.size()) + " maps");
  const double a = double(step.alpha);
  for (double& w : weights_) w *= 1.0 - a;
  weights_[step.selectedMap] += a;
}

double BlendedMapWeights::total() const {
  double s = 0.0;
  for (double w : weights_) s += w;
  return s;
}

}  // namespace swish::runtime
