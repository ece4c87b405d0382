#pragma once
// The run-time novelty guard's data (model.hpp NoveltyGuard, runtime/novelty_guard.hpp), fitted to the
// poses the network was trained on: k-means centres of their normalised Theta, the unit (the 95th
// percentile of the training poses' own distances to their nearest centre, so that novelty 1 is the
// sparse edge of the training set) and the range of each mesh weight over the training shapes (the
// clamp). The blend thresholds are chosen later, by measurement on held-out subjects
// (bake/report/subject_evaluation.hpp); until then the guard clamps only.
#include <cstdint>

#include "swish/core/types.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct NoveltyGuardFitOptions {
  // Centres: at most this many, and at most one per 8 training poses. Each costs thetaSize
  // multiply-adds per character per frame (bench_mlp: MLP + novelty).
  int centres = 128;
  uint64_t seed = 1;
  float flagAbove = 2.f;  // novelty reported as novel until the held-out study sets the blend start
};

// theta: D x n, the training poses' Theta (not normalised); meshWeights: K x n, their PCA weights.
// The model's inputNorm and thetaSize must already be final.
NoveltyGuard fitNoveltyGuard(const Model& model, const MatXf& theta, const MatXf& meshWeights,
                             const NoveltyGuardFitOptions& options = {});

}  // namespace swish::bake
