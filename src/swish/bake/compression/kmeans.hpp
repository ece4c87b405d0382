#pragma once
// k-means (Lloyd) with k-means++ seeding, used twice by the bake: over normal-map PCA codes (to pick
// the database maps) and over 4x4 texel blocks (to train the VQ codebook). Points are the ROWS of an
// N x D matrix.
//  - Seeding: k-means++ with a seeded Rng. When fewer than k distinct points exist, seeding stops at
//    the number of distinct points (every remaining point already coincides with a centre), so the
//    result may have fewer than k clusters; it never has two identical centres from the seeding.
//  - Empty clusters (a centre that lost all its points) are re-seeded at the point currently worst
//    served by its centre, so no centre is ever left undefined.
//  - Deterministic for a seed and independent of the thread count: assignments are computed in
//    parallel (each point on its own), centre sums are reduced in a fixed order in double.
#include <cstdint>
#include <vector>

#include "swish/core/types.hpp"

namespace swish::bake {

struct KMeansOptions {
  int clusters = 8;
  int maxIterations = 50;
  // Stop when the relative decrease of the inertia over one iteration falls below this.
  double relativeTolerance = 1e-5;
  uint64_t seed = 1;
  // k-means++ draws its candidates from at most this many points (0: all). Seeding costs N x k
  // distance evaluations; for the VQ's large training sets a subsample is plenty.
  int seedingSampleLimit = 0;
};

using RowMatXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct KMeansResult {
  RowMatXf centres;                  // clusters x D
  std::vector<uint32_t> assignment;  // per point, its centre
  std::vector<uint32_t> clusterSizes;
  double inertia = 0.0;  // sum of squared distances to the assigned centre
  int iterations = 0;
};

KMeansResult kMeans(const RowMatXf& points, const KMeansOptions& options);

// Nearest centre of every point (squared Euclidean; ties -> lowest index), computed in blocks through
// matrix products so that a million points against thousands of centres stays fast. Optionally
// returns the squared distances.
std::vector<uint32_t> nearestCentres(const RowMatXf& points, const RowMatXf& centres,
                                     std::vector<float>* squaredDistances = nullptr);

}  // namespace swish::bake
