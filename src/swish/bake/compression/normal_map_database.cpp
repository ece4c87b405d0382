#include "swish/bake/compression/normal_map_database.hpp"

#include <limits>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

DatabaseSelection selectDatabaseMaps(const MatXf& codes, int count, uint64_t seed) {
  if (codes.cols() == 0) throw Error("normal-map database: no maps to choose from");
  if (count < 1) throw Error("normal-map database: size must be >= 1, got " + std::to_string(count));
  const RowMatXf points = codes.transpose();
  KMeansOptions o;
  o.clusters = count;
  o.maxIterations = 100;
  o.seed = seed;
  const KMeansResult km = kMeans(points, o);

  DatabaseSelection s;
  s.inertia = km.inertia;
  s.iterations = km.iterations;
  const Eigen::Index k = km.centres.rows();
  std::vector<double> best(size_t(k), std::numeric_limits<double>::infinity());
  std::vector<int64_t> bestMap(size_t(k), -1);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const uint32_t c = km.assignment[size_t(i)];
    const double d = (points.row(i) - km.centres.row(c)).cast<double>().squaredNorm();
    if (d < best[c]) best[c] = d, bestMap[c] = i;
  }
  // Re-seeding guarantees no empty cluster, but keep only filled ones in case of exact ties.
  for (Eigen::Index c = 0; c < k; ++c)
    if (bestMap[size_t(c)] >= 0) s.mapIndices.push_back(uint32_t(bestMap[size_t(c)]));
  s.keys.resize(Eigen::Index(s.mapIndices.size()), codes.rows());
  for (size_t e = 0; e < s.mapIndices.size(); ++e) s.keys.row(Eigen::Index(e)) = codes.col(s.mapIndices[e]).transpose();
  // Each map's entry is the nearest KEY (what the runtime will pick for it), not its k-means cluster.
  s.clusterOf.resize(size_t(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) s.clusterOf[size_t(i)] = nearestKey(s.keys, codes.col(i));
  return s;
}

uint32_t nearestKey(const MatXf& keys, const VecXf& code) {
  if (keys.rows() == 0) throw Error("normal-map database: lookup in an empty database");
  if (keys.cols() != code.size())
    throw Error("normal-map database: code of " + std::to_string(code.size()) + " dims, keys have " +
                std::to_string(keys.cols()));
  uint32_t bestRow = 0;
  float best = std::numeric_limits<float>::infinity();
  for (Eigen::Index r = 0; r < keys.rows(); ++r) {
    const float d = (keys.row(r).transpose() - code).squaredNorm();
    if (d < best) best = d, bestRow = uint32_t(r);
  }
  return bestRow;
}

}  // namespace swish::bake
