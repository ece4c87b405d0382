#include "swish/bake/training/distillation.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <string>

#include "swish/bake/poses/pose_synthesis.hpp"
#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

namespace {

// For each column of `x` (standardised), the indices of its `k` nearest other columns, nearest first.
std::vector<std::vector<uint32_t>> nearestColumns(const MatXd& x, int k) {
  const Eigen::Index n = x.cols();
  const VecXd norms = x.colwise().squaredNorm().transpose();
  std::vector<std::vector<uint32_t>> out(static_cast<size_t>(n));
  std::vector<uint32_t> order(static_cast<size_t>(n));
  std::vector<double> d(static_cast<size_t>(n));
  const size_t take = std::min<size_t>(size_t(k), size_t(n) - 1);
  for (Eigen::Index j = 0; j < n; ++j) {
    const VecXd dots = x.transpose() * x.col(j);
    for (Eigen::Index i = 0; i < n; ++i) d[size_t(i)] = norms[i] + norms[j] - 2.0 * dots[i];
    d[size_t(j)] = std::numeric_limits<double>::infinity();
    std::iota(order.begin(), order.end(), 0u);
    std::partial_sort(order.begin(), order.begin() + long(take), order.end(),
                      [&](uint32_t a, uint32_t b) { return d[a] < d[b] || (d[a] == d[b] && a < b); });
    out[size_t(j)].assign(order.begin(), order.begin() + long(take));
  }
  return out;
}

}  // namespace

DistilledSamples distilledSamples(std::span<const Pose* const> poses, std::span<const uint32_t> inputJoints,
                                  bool rootGravity, const MatXf& theta, const MatXf& lambda, const DistillSettings& s) {
  const size_t n = poses.size();
  if (size_t(theta.cols()) != n || size_t(lambda.cols()) != n)
    throw Error("train.distill: " + std::to_string(n) + " poses, " + std::to_string(theta.cols()) + " inputs and " +
                std::to_string(lambda.cols()) + " targets");
  if (n < 4) throw Error("train.distill: needs at least 4 training poses, got " + std::to_string(n));
  if (!(s.mixShare >= 0.0 && s.mixShare <= 1.0)) throw Error("train.distill: mix_share must be in [0, 1]");
  if (!(s.swapProbability > 0.0 && s.swapProbability <= 1.0))
    throw Error("train.distill: swap_probability must be in (0, 1]");
  if (s.neighbours < 1) throw Error("train.distill: neighbours must be at least 1");
  if (inputJoints.empty()) throw Error("train.distill: the network has no input joints to vary");
  for (const Pose* p : poses)
    for (uint32_t j : inputJoints)
      if (j >= p->local.size()) throw Error("train.distill: an input joint is outside a training pose's skeleton");

  DistilledSamples out;
  out.teacher = fitKernelRidge(theta, lambda, s.teacher);
  // The teacher's centres are the training inputs standardised: the space the neighbours are found in.
  const std::vector<std::vector<uint32_t>> near = nearestColumns(out.teacher.centres, s.neighbours);

  Rng rng(s.seed);
  out.theta.resize(theta.rows(), Eigen::Index(s.poses));
  std::vector<Quatf> local;
  for (size_t i = 0; i < s.poses; ++i) {
    const size_t base = size_t(rng.below(n));
    local = poses[base]->local;
    if (rng.uniform() < s.mixShare) {
      ++out.mixes;
      bool swapped = false;
      for (uint32_t j : inputJoints)
        if (rng.uniform() < s.swapProbability) local[j] = poses[size_t(rng.below(n))]->local[j], swapped = true;
      if (!swapped) {  // at least one joint from elsewhere, else the sample is the training pose itself
        const uint32_t j = inputJoints[size_t(rng.below(inputJoints.size()))];
        local[j] = poses[size_t(rng.below(n))]->local[j];
      }
    } else {
      ++out.blends;
      const std::vector<uint32_t>& candidates = near[base];
      const Pose& partner = *poses[candidates[size_t(rng.below(candidates.size()))]];
      const float t = rng.uniformf(0.f, 1.f);
      for (uint32_t j : inputJoints) local[j] = rotationBetween(local[j], partner.local[j], t);
    }
    const std::vector<float> th = runtime::computeTheta(inputJoints, rootGravity, local);
    out.theta.col(Eigen::Index(i)) = Eigen::Map<const VecXf>(th.data(), Eigen::Index(th.size()));
  }
  out.lambda = out.teacher.predict(out.theta);
  return out;
}

}  // namespace swish::bake
