#include "swish/bake/compression/kmeans.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {

std::vector<uint32_t> nearestCentres(const RowMatXf& points, const RowMatXf& centres,
                                     std::vector<float>* squaredDistances) {
  const Eigen::Index n = points.rows(), k = centres.rows();
  if (k == 0) throw Error("k-means: no centres to assign points to");
  if (centres.cols() != points.cols()) throw Error("k-means: centres and points differ in dimension");
  std::vector<uint32_t> out(size_t(n), 0);
  if (squaredDistances) squaredDistances->assign(size_t(n), 0.f);
  const Eigen::VectorXf centreNorms = centres.rowwise().squaredNorm();
  constexpr Eigen::Index kChunk = 1024;
  const Eigen::Index chunks = (n + kChunk - 1) / kChunk;
  tbb::parallel_for(Eigen::Index(0), chunks, [&](Eigen::Index c) {
    const Eigen::Index begin = c * kChunk, rows = std::min(kChunk, n - begin);
    // |p - c|^2 = |p|^2 - 2 p.c + |c|^2; |p|^2 is the same for every centre of a point, so the
    // argmin only needs |c|^2 - 2 p.c.
    MatXf dots = points.middleRows(begin, rows) * centres.transpose();  // rows x k
    for (Eigen::Index i = 0; i < rows; ++i) {
      float best = std::numeric_limits<float>::infinity();
      Eigen::Index bestJ = 0;
      for (Eigen::Index j = 0; j < k; ++j) {
        const float d = centreNorms[j] - 2.f * dots(i, j);
        if (d < best) best = d, bestJ = j;
      }
      out[size_t(begin + i)] = uint32_t(bestJ);
      if (squaredDistances) {
        // The expanded form cancels badly near 0; recompute the chosen distance directly.
        (*squaredDistances)[size_t(begin + i)] = (points.row(begin + i) - centres.row(bestJ)).squaredNorm();
      }
    }
  });
  return out;
}

namespace {

RowMatXf seedPlusPlus(const RowMatXf& points, int k, Rng& rng, int sampleLimit) {
  const Eigen::Index n = points.rows();
  // Candidate pool: all points, or an evenly strided deterministic subset.
  std::vector<Eigen::Index> pool;
  if (sampleLimit > 0 && n > sampleLimit) {
    pool.reserve(size_t(sampleLimit));
    for (int i = 0; i < sampleLimit; ++i) pool.push_back(Eigen::Index(double(i) * double(n) / sampleLimit));
  } else {
    pool.resize(size_t(n));
    for (Eigen::Index i = 0; i < n; ++i) pool[size_t(i)] = i;
  }
  std::vector<double> d2(pool.size(), std::numeric_limits<double>::infinity());
  std::vector<Eigen::Index> chosen;
  chosen.push_back(pool[rng.below(pool.size())]);
  auto update = [&](Eigen::Index centre) {
    tbb::parallel_for(size_t(0), pool.size(), [&](size_t i) {
      d2[i] = std::min(d2[i], double((points.row(pool[i]) - points.row(centre)).squaredNorm()));
    });
  };
  update(chosen.back());
  while (int(chosen.size()) < k) {
    double total = 0.0;
    for (double v : d2) total += v;
    if (!(total > 0.0)) break;  // every point coincides with a centre: no more distinct points
    double target = rng.uniform() * total;
    size_t pick = pool.size() - 1;
    for (size_t i = 0; i < pool.size(); ++i) {
      target -= d2[i];
      if (target < 0.0 && d2[i] > 0.0) {
        pick = i;
        break;
      }
    }
    while (d2[pick] == 0.0 && pick > 0) --pick;  // rounding at the end of the scan: stay on a new point
    if (d2[pick] == 0.0) break;
    chosen.push_back(pool[pick]);
    update(chosen.back());
  }
  RowMatXf centres(chosen.size(), points.cols());
  for (size_t c = 0; c < chosen.size(); ++c) centres.row(Eigen::Index(c)) = points.row(chosen[c]);
  return centres;
}

}  // namespace

KMeansResult kMeans(const RowMatXf& points, const KMeansOptions& o) {
  if (points.rows() == 0) throw Error("k-means: no points");
  if (o.clusters < 1) throw Error("k-means: clusters must be >= 1, got " + std::to_string(o.clusters));
  if (o.maxIterations < 0) throw Error("k-means: maxIterations must be >= 0");
  if (!points.allFinite()) throw Error("k-means: points contain NaN or Inf");
  Rng rng(o.seed);
  KMeansResult r;
  r.centres = seedPlusPlus(points, int(std::min<Eigen::Index>(o.clusters, points.rows())), rng, o.seedingSampleLimit);
  const Eigen::Index k = r.centres.rows(), dims = points.cols();

  std::vector<float> d2;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    r.assignment = nearestCentres(points, r.centres, &d2);
    r.inertia = 0.0;
    for (float v : d2) r.inertia += v;
    r.iterations = it;
    const bool converged =
        r.inertia == 0.0 || (std::isfinite(previous) && previous - r.inertia <= o.relativeTolerance * previous);
    if (it >= o.maxIterations || converged) break;
    previous = r.inertia;

    // Update: mean of the members, summed in point order (deterministic).
    MatXd sums = MatXd::Zero(k, dims);
    std::vector<uint32_t> counts(size_t(k), 0);
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      sums.row(r.assignment[size_t(i)]) += points.row(i).cast<double>();
      ++counts[r.assignment[size_t(i)]];
    }
    // Empty clusters take the worst-served points, one each, worst first; those points are then
    // marked so two empty clusters never take the same point.
    std::vector<Eigen::Index> order;
    size_t emptyThisIteration = 0;
    for (Eigen::Index c = 0; c < k; ++c) {
      if (counts[size_t(c)] > 0) {
        r.centres.row(c) = (sums.row(c) / double(counts[size_t(c)])).cast<float>();
        continue;
      }
      if (order.empty()) {
        order.resize(size_t(points.rows()));
        for (Eigen::Index i = 0; i < points.rows(); ++i) order[size_t(i)] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](Eigen::Index a, Eigen::Index b) { return d2[size_t(a)] > d2[size_t(b)]; });
      }
      const size_t taken = emptyThisIteration++ % order.size();
      r.centres.row(c) = points.row(order[taken]);
    }
  }
  r.clusterSizes.assign(size_t(k), 0);
  for (uint32_t a : r.assignment) ++r.clusterSizes[a];
  return r;
}

}  // namespace swish::bake
