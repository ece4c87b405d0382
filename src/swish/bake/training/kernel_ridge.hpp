#pragma once
// Kernel ridge regression with a Gaussian kernel (the pose-space interpolation of Lewis et al. 2000, with
// a ridge), fitted on standardised inputs: a smooth regressor of few assumptions that part 2 uses as a
// teacher (train.distill, part2_training.hpp): it labels poses between the training poses, and the MLP
// learns from those labels as well as from the simulated ones.
//
//   x       = (input - inputNorm.mean) / inputNorm.scale
//   k(x, c) = exp(-|x - c|^2 / (2 width^2))
//   f(x)    = outputMean + sum_i alpha_i k(x, c_i)            (c_i: the training inputs, standardised)
//   alpha   = (K + lambda I)^-1 (Y - outputMean)
//
// The width is a multiple of the median distance from a training input to its nearest other one; the
// multiple and lambda are chosen from grids by the weighted squared error on a seeded validation share of
// the samples, then refitted on all of them. Deterministic for a seed.
#include <cstdint>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct KernelRidgeOptions {
  std::vector<double> widthScales{0.5, 0.75, 1.0, 1.5, 2.0, 3.0};  // times the median nearest distance
  std::vector<double> lambdas{0.003, 0.01, 0.03, 0.1, 0.3, 1.0};
  double validationFraction = 0.1;
  uint64_t seed = 1;
  std::vector<double> outputWeights;  // per output in the validation error (empty: all 1)
};

struct KernelRidgeFit {
  Normalisation inputNorm;
  Eigen::MatrixXd centres;  // D x N, the standardised training inputs
  Eigen::MatrixXd alpha;    // N x M
  Eigen::VectorXd outputMean;
  double nearestMedian = 0.0;  // median distance to the nearest other training input (standardised)
  double widthScale = 0.0, width = 0.0, lambda = 0.0;
  double validationError = 0.0;  // weighted mean squared error per validation sample at the chosen pair
  struct Trial {
    double widthScale = 0.0, lambda = 0.0, validationError = 0.0;
  };
  std::vector<Trial> trials;  // every pair tried, in grid order

  // Outputs (M x n) for inputs (D x n), unstandardised as the training inputs were given.
  MatXf predict(const MatXf& inputs) const;
};

// inputs D x N, outputs M x N (N >= 4: a validation share of at least one sample and three to fit).
// Throws Error for non-finite data, mismatched sizes, too few samples, empty or non-positive grids.
KernelRidgeFit fitKernelRidge(const MatXf& inputs, const MatXf& outputs, const KernelRidgeOptions& options = {});

}  // namespace swish::bake
