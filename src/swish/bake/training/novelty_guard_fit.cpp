#include "swish/bake/training/novelty_guard_fit.hpp"

#include <algorithm>
#include <vector>

#include "swish/bake/compression/kmeans.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/novelty_guard.hpp"

namespace swish::bake {

NoveltyGuard fitNoveltyGuard(const Model& model, const MatXf& theta, const MatXf& meshWeights,
                             const NoveltyGuardFitOptions& o) {
  const Eigen::Index D = model.thetaSize(), n = theta.cols();
  if (theta.rows() != D || n == 0 || meshWeights.cols() != n || meshWeights.rows() != model.meshComponents())
    throw Error("novelty guard fit: " + std::to_string(theta.rows()) + " x " + std::to_string(n) + " inputs and " +
                std::to_string(meshWeights.rows()) + " x " + std::to_string(meshWeights.cols()) +
                " weights for a Theta of " + std::to_string(D) + " and " + std::to_string(model.meshComponents()) +
                " components");
  RowMatXf x(n, D);
  for (Eigen::Index i = 0; i < n; ++i)
    x.row(i) = ((theta.col(i) - model.inputNorm.mean).cwiseQuotient(model.inputNorm.scale)).transpose();
  KMeansOptions ko;
  ko.clusters = std::max(1, std::min(o.centres, int(n / 8)));
  ko.seed = o.seed;
  const KMeansResult km = kMeans(x, ko);

  NoveltyGuard g;
  g.centres = km.centres;
  g.unit = 1.f;
  g.weightMin = meshWeights.rowwise().minCoeff();
  g.weightMax = meshWeights.rowwise().maxCoeff();
  g.flagAbove = o.flagAbove;
  // The unit from the run time's own measure, so that the bake and the run time agree to the bit.
  Model probe;
  probe.inputJoints = model.inputJoints;
  probe.rootGravity = model.rootGravity;
  probe.inputNorm = model.inputNorm;
  probe.noveltyGuard = g;
  const runtime::NoveltyGuardEvaluator eval(probe);
  std::vector<float> d(static_cast<size_t>(n));
  eval.measure(std::span<const float>(theta.data(), size_t(theta.size())), uint32_t(n), d);
  const size_t k = std::min(d.size() - 1, size_t(0.95 * double(d.size())));
  std::nth_element(d.begin(), d.begin() + long(k), d.end());
  g.unit = std::max(d[k], 1e-6f);
  return g;
}

}  // namespace swish::bake
