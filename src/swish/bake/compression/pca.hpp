#pragma once
// Principal component analysis of sample vectors, shared by the mesh PCA (game-mesh shapes in
// pre-skinning space) and the normal-map PCA (database keys). Samples are the COLUMNS of a D x N
// matrix. Two methods:
//  - exact: a bidiagonal divide-and-conquer SVD (Eigen BDCSVD) of the centred data, in double;
//  - randomised (Halko, Martinsson, Tropp 2011): a seeded Gaussian sketch with power iterations, for
//    data too large for a dense SVD (128+ normal maps of 360x360x2 values). Centring is applied
//    implicitly so the (possibly huge) input is never copied.
// Either way the total variance is known exactly, so explained variance and truncation error per K
// are exact for every K that was computed.
#include <cstdint>

#include "swish/core/types.hpp"

namespace swish::bake {

struct PcaOptions {
  enum class Method { Auto, Exact, Randomized };
  int maxComponents = 0;         // K upper bound (0: as many as the data allows)
  double varianceToKeep = 0.0;   // in (0, 1]: smallest K whose explained variance reaches it; 0: unused
  Method method = Method::Auto;  // Auto: Exact when D * N <= exactLimit, else Randomized
  double exactLimit = 2.5e7;
  int oversampling = 10;    // randomised: extra sketch columns
  int powerIterations = 3;  // randomised: sharpen the spectrum of the sketch
  uint64_t seed = 1;
};

struct PcaResult {
  VecXf mean;                     // D
  MatXf basis;                    // D x K, orthonormal columns, by decreasing variance
  VecXd singularValues;           // of the centred data, for every computed component (>= K)
  double totalSquaredNorm = 0.0;  // sum over samples of |x - mean|^2
  // Per computed K (index K, 0 .. singularValues.size()): fraction of the variance explained by the
  // first K components (1 for zero-variance data), and the residual sum of squares left over.
  VecXd explainedVariance;
  VecXd residualSquaredNorm;
  int sampleCount = 0;
  bool randomized = false;

  int components() const { return int(basis.cols()); }
  // Codes (K x M) of the given samples (D x M).
  MatXf project(const MatXf& samples) const;
  // Samples (D x M) from codes (K x M).
  MatXf reconstruct(const MatXf& codes) const;
};

// Throws Error (naming `what`) for empty or non-finite data or inconsistent options.
PcaResult fitPca(const MatXf& samples, const PcaOptions& options, const char* what = "pca");

}  // namespace swish::bake
