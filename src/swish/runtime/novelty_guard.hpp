#pragma once
// The run-time novelty guard: per character per frame, how far this frame's network input lies from
// the poses the model was trained on, and mesh weights kept safe where it is far (model.hpp,
// NoveltyGuard, has the definitions and the bake fits them: bake/training/novelty_guard_fit.hpp).
//
//   x       = (Theta - inputNorm.mean) / inputNorm.scale              (the network's own input space)
//   novelty = sqrt(min_c |x - centre_c|^2 / D) / unit                  (D = Theta's size)
//   weights = clamp(weights, weightMin, weightMax) * (1 - b),  b = clamp((novelty - blendStart) /
//             (blendEnd - blendStart), 0, 1) when the guard blends, else 0: towards the PCA mean shape.
//
// The distances of a batch are one C x D by D x n product (|x - c|^2 = |x|^2 - 2 c.x + |c|^2), so the
// cost is C*D multiply-adds per character next to the MLP's tens of thousands (bench_mlp measures it).
// A non-finite input has novelty +inf: the guard then gives the mean shape.
#include <cstdint>
#include <span>

#include "swish/core/types.hpp"
#include "swish/model/model.hpp"

namespace swish::runtime {

// The guard's clamp and blend of one character's K mesh weights for its novelty, with the thresholds and
// ranges of `guard` (its centres are not used): the run time applies the model's guard with it, the
// bake's study (bake/report/subject_evaluation.cpp) the settings it compares. Empty weight ranges: no
// clamp; blendEnd <= blendStart: no blend; NaN novelty blends fully.
void applyNoveltyGuard(const NoveltyGuard& guard, float novelty, std::span<float> meshWeights);
float noveltyBlend(const NoveltyGuard& guard, float novelty);

class NoveltyGuardEvaluator {
 public:
  // The model's guard may be empty (a model before format 1.2): then active() is false, novelty() is
  // not measured and apply() changes nothing.
  explicit NoveltyGuardEvaluator(const Model& model);

  bool active() const { return centres_.rows() > 0; }
  const NoveltyGuard& guard() const { return guard_; }

  // theta: n characters' Theta, one after the other (n x D). novelty: n values. Not thread-safe (one
  // evaluator per thread): it keeps its scratch between calls, so a frame allocates nothing.
  void measure(std::span<const float> theta, uint32_t n, std::span<float> novelty) const;
  float measureOne(std::span<const float> theta) const;

  // One character's K mesh weights, clamped and blended for its novelty.
  void apply(float novelty, std::span<float> meshWeights) const;
  // The blend factor towards the mean shape for a novelty (0: none, 1: the mean shape).
  float blendOf(float novelty) const;

 private:
  NoveltyGuard guard_;
  MatXf centres_;     // C x D
  VecXf centreNorm_;  // C: |centre|^2
  VecXf mean_, invScale_;
  mutable MatXf x_, dots_;
};

}  // namespace swish::runtime
