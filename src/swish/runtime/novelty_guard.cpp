#include "swish/runtime/novelty_guard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

NoveltyGuardEvaluator::NoveltyGuardEvaluator(const Model& model) : guard_(model.noveltyGuard) {
  if (guard_.empty()) return;
  if (guard_.centres.cols() != model.thetaSize() || model.inputNorm.mean.size() != model.thetaSize())
    throw Error("novelty guard: centres of " + std::to_string(guard_.centres.cols()) + " inputs for a Theta of " +
                std::to_string(model.thetaSize()));
  centres_ = guard_.centres;
  centreNorm_ = centres_.rowwise().squaredNorm();
  mean_ = model.inputNorm.mean;
  invScale_ = model.inputNorm.scale.cwiseInverse();
}

void NoveltyGuardEvaluator::measure(std::span<const float> theta, uint32_t n, std::span<float> novelty) const {
  if (!active()) {  // no guard: nothing to measure against
    if (novelty.size() != n)
      throw Error("novelty guard: " + std::to_string(novelty.size()) + " outputs for " + std::to_string(n) +
                  " characters");
    std::fill(novelty.begin(), novelty.end(), std::numeric_limits<float>::quiet_NaN());
    return;
  }
  const Eigen::Index D = centres_.cols();
  if (novelty.size() != n || theta.size() != size_t(n) * size_t(D))
    throw Error("novelty guard: " + std::to_string(theta.size()) + " inputs and " + std::to_string(novelty.size()) +
                " outputs for " + std::to_string(n) + " characters of " + std::to_string(D) + " inputs");
  const Eigen::Map<const MatXf> t(theta.data(), D, Eigen::Index(n));
  x_.resize(D, Eigen::Index(n));
  x_.noalias() = ((t.colwise() - mean_).array().colwise() * invScale_.array()).matrix();
  dots_.resize(centres_.rows(), Eigen::Index(n));
  dots_.noalias() = centres_ * x_;
  const float invD = 1.f / float(D), invUnit = 1.f / guard_.unit;
  for (uint32_t i = 0; i < n; ++i) {
    const float xx = x_.col(i).squaredNorm();
    if (!std::isfinite(xx)) {
      novelty[i] = std::numeric_limits<float>::infinity();
      continue;
    }
    float best = std::numeric_limits<float>::max();
    for (Eigen::Index c = 0; c < centres_.rows(); ++c) best = std::min(best, centreNorm_[c] - 2.f * dots_(c, i));
    novelty[i] = std::sqrt(std::max(0.f, best + xx) * invD) * invUnit;
  }
}

float NoveltyGuardEvaluator::measureOne(std::span<const float> theta) const {
  float v = 0.f;
  measure(theta, 1, std::span<float>(&v, 1));
  return v;
}

float noveltyBlend(const NoveltyGuard& g, float novelty) {
  if (!g.blends()) return 0.f;
  if (!(novelty == novelty)) return 1.f;  // NaN: as far as it gets
  return std::clamp((novelty - g.blendStart) / (g.blendEnd - g.blendStart), 0.f, 1.f);
}

void applyNoveltyGuard(const NoveltyGuard& g, float novelty, std::span<float> w) {
  if (g.weightMin.size() > 0) {
    if (w.size() != size_t(g.weightMin.size()))
      throw Error("novelty guard: " + std::to_string(w.size()) + " mesh weights for ranges of " +
                  std::to_string(g.weightMin.size()));
    for (size_t k = 0; k < w.size(); ++k)
      w[k] = std::isnan(w[k]) ? 0.f : std::clamp(w[k], g.weightMin[Eigen::Index(k)], g.weightMax[Eigen::Index(k)]);
  }
  const float keep = 1.f - noveltyBlend(g, novelty);
  if (keep < 1.f)
    for (float& v : w) v *= keep;
}

float NoveltyGuardEvaluator::blendOf(float novelty) const { return active() ? noveltyBlend(guard_, novelty) : 0.f; }

void NoveltyGuardEvaluator::apply(float novelty, std::span<float> w) const {
  if (active()) applyNoveltyGuard(guard_, novelty, w);
}

}  // namespace swish::runtime
