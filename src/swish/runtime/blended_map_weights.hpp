#pragma once
// The CPU model of a character's temporally filtered normal map, as weights over the database maps:
//     output map = sum_m weight[m] * decoded(map m).
// Applying the BlendSteps of TemporalFilter in order gives exactly (in real arithmetic) what the GPU
// blend pass computes texel by texel with out = mix(out, decoded(selected), alpha), so tests and the
// replay can build the expected map from the decoded database maps. Weights are kept in double, so
// their rounding is far below the GPU's float blend; they always sum to 1 (within rounding) once a first
// step has been applied.
#include <cstdint>
#include <vector>

#include "swish/runtime/temporal_filter.hpp"

namespace swish::runtime {

class BlendedMapWeights {
 public:
  explicit BlendedMapWeights(uint32_t mapCount) : weights_(mapCount, 0.0) {}

  // weight = (1 - alpha) * weight + alpha * onehot(selected). A first-frame step (alpha 1) replaces
  // the history. Throws Error if step.selectedMap is outside the database.
  void apply(const BlendStep& step);

  const std::vector<double>& weights() const { return weights_; }
  double weight(uint32_t map) const { return weights_.at(map); }
  // Sum of the weights: 0 before the first step, 1 after (up to rounding).
  double total() const;

 private:
  std::vector<double> weights_;
};

}  // namespace swish::runtime
