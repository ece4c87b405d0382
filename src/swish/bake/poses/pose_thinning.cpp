#include "swish/bake/poses/pose_thinning.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <array>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

constexpr int kAxes = 3;  // principal axes: the first orders the band search, the others pre-filter

// Squared distance with an early exit once it exceeds `limit` (most candidates are far).
inline bool withinSquared(const float* a, const float* b, int dim, float limit) {
  float s = 0.f;
  int k = 0;
  for (; k + 8 <= dim; k += 8) {
    for (int j = 0; j < 8; ++j) {
      const float d = a[k + j] - b[k + j];
      s += d * d;
    }
    if (s > limit) return false;
  }
  for (; k < dim; ++k) {
    const float d = a[k] - b[k];
    s += d * d;
  }
  return s <= limit;
}

// The samples' three principal axes (from at most ~16k evenly spaced samples): projections on them are
// as spread out as projections get, so the band search and the pre-filters reject the most.
std::array<std::vector<float>, kAxes> principalAxes(const PoseSamples& samples) {
  const int dim = samples.dim;
  const size_t n = samples.size();
  const size_t stride = std::max<size_t>(1, n / 16384);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(dim);
  size_t m = 0;
  for (size_t i = 0; i < n; i += stride, ++m)
    for (int k = 0; k < dim; ++k) mean[k] += samples.row(i)[k];
  std::array<std::vector<float>, kAxes> axes;
  if (m == 0) {
    for (int a = 0; a < kAxes; ++a) axes[size_t(a)].assign(size_t(dim), a < dim && a == 0 ? 1.f : 0.f);
    return axes;
  }
  mean /= double(m);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(dim, dim);
  for (size_t i = 0; i < n; i += stride) {
    Eigen::VectorXd x(dim);
    for (int k = 0; k < dim; ++k) x[k] = samples.row(i)[k] - mean[k];
    cov.selfadjointView<Eigen::Lower>().rankUpdate(x);
  }
  cov = cov.selfadjointView<Eigen::Lower>();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  for (int a = 0; a < kAxes; ++a) {
    axes[size_t(a)].assign(size_t(dim), 0.f);
    if (a >= dim) continue;
    const Eigen::VectorXd v = eig.eigenvectors().col(dim - 1 - a);  // ascending eigenvalues
    for (int k = 0; k < dim; ++k) axes[size_t(a)][size_t(k)] = float(v[k]);
  }
  return axes;
}

void checkKeepFirst(const PoseSamples& samples, std::span<const uint32_t> keepFirst) {
  std::vector<bool> seen(samples.size(), false);
  for (uint32_t k : keepFirst) {
    if (k >= samples.size())
      throw Error("pose thinning: pose to keep " + std::to_string(k) + " is not among the " +
                  std::to_string(samples.size()) + " samples");
    if (seen[k]) throw Error("pose thinning: pose to keep " + std::to_string(k) + " is listed twice");
    seen[k] = true;
  }
}

void checkSamples(const PoseSamples& samples) {
  if (samples.dim <= 0) throw Error("pose thinning: samples have dimension " + std::to_string(samples.dim));
  if (samples.values.size() % size_t(samples.dim) != 0)
    throw Error("pose thinning: " + std::to_string(samples.values.size()) + " values is not a multiple of dimension " +
                std::to_string(samples.dim));
  for (size_t i = 0; i < samples.values.size(); ++i)
    if (!std::isfinite(samples.values[i]))
      throw Error("pose thinning: sample " + std::to_string(i / size_t(samples.dim)) + " is not finite");
}

// The kept set: rows copied contiguously, plus their projections, sorted by the first, for the band
// search. Projections never increase distances, so a kept pose whose projection on any axis differs
// by more than the tolerance cannot cover the query.
class KeptPoses {
 public:
  using Projection = std::array<float, kAxes>;
  KeptPoses(int dim, const std::array<std::vector<float>, kAxes>& axes) : dim_(dim), axes_(axes) {}

  Projection project(const float* x) const {
    Projection p{};
    for (int a = 0; a < kAxes; ++a) {
      float s = 0.f;
      for (int k = 0; k < dim_; ++k) s += x[k] * axes_[size_t(a)][size_t(k)];
      p[size_t(a)] = s;
    }
    return p;
  }
  size_t size() const { return sampleIndex_.size(); }
  const float* row(size_t k) const { return rows_.data() + k * size_t(dim_); }
  uint32_t sampleIndex(size_t k) const { return sampleIndex_[k]; }

  // Index of some kept pose within sqrt(limitSq) of x (projection p), or -1.
  long findWithin(const float* x, const Projection& p, float tol, float limitSq, size_t& checks) const {
    auto lo = std::lower_bound(order_.begin(), order_.end(), p[0] - tol,
                               [](const Entry& e, float v) { return e.proj[0] < v; });
    for (auto it = lo; it != order_.end() && it->proj[0] <= p[0] + tol; ++it) {
      bool far = false;
      for (int a = 1; a < kAxes; ++a) far = far || std::abs(it->proj[size_t(a)] - p[size_t(a)]) > tol;
      if (far) continue;
      ++checks;
      if (withinSquared(x, row(it->slot), dim_, limitSq)) return long(it->slot);
    }
    return -1;
  }

  void add(const float* x, const Projection& p, uint32_t sample) {
    const size_t slot = size();
    rows_.insert(rows_.end(), x, x + dim_);
    sampleIndex_.push_back(sample);
    Entry e{p, uint32_t(slot)};
    order_.insert(std::upper_bound(order_.begin(), order_.end(), e,
                                   [](const Entry& a, const Entry& b) { return a.proj[0] < b.proj[0]; }),
                  e);
  }

 private:
  struct Entry {
    Projection proj;
    uint32_t slot;
  };
  int dim_;
  const std::array<std::vector<float>, kAxes>& axes_;
  std::vector<float> rows_;
  std::vector<uint32_t> sampleIndex_;
  std::vector<Entry> order_;
};

ThinningResult thinPass(const PoseSamples& samples, float tolerance, size_t maxKept,
                        const std::array<std::vector<float>, kAxes>& axes, std::span<const uint32_t> keepFirst) {
  if (!(tolerance >= 0.f) || !std::isfinite(tolerance))
    throw Error("pose thinning: tolerance " + std::to_string(tolerance) + " must be finite and >= 0");
  const int dim = samples.dim;
  const size_t n = samples.size();
  // "Farther than the tolerance" keeps a pose; distance <= tolerance rejects it.
  const float limitSq = tolerance * tolerance;
  KeptPoses kept(dim, axes);
  ThinningResult result;
  result.tolerance = tolerance;
  for (uint32_t k : keepFirst) kept.add(samples.row(k), kept.project(samples.row(k)), k);
  long lastCover = -1;
  for (size_t i = 0; i < n; ++i) {
    const float* x = samples.row(i);
    if (lastCover >= 0) {
      ++result.distanceChecks;
      if (withinSquared(x, kept.row(size_t(lastCover)), dim, limitSq)) continue;
    }
    const auto p = kept.project(x);
    const long cover = kept.findWithin(x, p, tolerance, limitSq, result.distanceChecks);
    if (cover >= 0) {
      lastCover = cover;
      continue;
    }
    if (kept.size() >= maxKept) {
      result.truncated = true;
      break;
    }
    kept.add(x, p, uint32_t(i));
    lastCover = long(kept.size() - 1);
  }
  result.kept.resize(kept.size());
  for (size_t k = 0; k < kept.size(); ++k) result.kept[k] = kept.sampleIndex(k);
  return result;
}

}  // namespace

ThinningResult thinPoses(const PoseSamples& samples, float tolerance, size_t maxKept,
                         std::span<const uint32_t> keepFirst) {
  checkSamples(samples);
  checkKeepFirst(samples, keepFirst);
  ThinningResult r = thinPass(samples, tolerance, maxKept, principalAxes(samples), keepFirst);
  r.truncated = r.truncated || keepFirst.size() > maxKept;
  return r;
}

float nearestKeptDistance(const PoseSamples& samples, const std::vector<uint32_t>& kept, std::span<const float> x) {
  if (x.size() != size_t(samples.dim))
    throw Error("pose thinning: a pose of " + std::to_string(x.size()) + " values against samples of " +
                std::to_string(samples.dim));
  double best = INFINITY;
  for (uint32_t k : kept) {
    const float* r = samples.row(k);
    double d = 0;
    for (int i = 0; i < samples.dim; ++i) d += double(r[i] - x[size_t(i)]) * double(r[i] - x[size_t(i)]);
    best = std::min(best, d);
  }
  return float(std::sqrt(best));
}

ThinningResult thinPosesToCount(const PoseSamples& samples, size_t target, const ThinToCountOptions& options) {
  checkSamples(samples);
  const std::span<const uint32_t> first = options.keepFirst;
  checkKeepFirst(samples, first);
  const size_t n = samples.size();
  if (target == 0) throw Error("pose thinning: target count must be at least 1");
  if (n == 0) throw Error("pose thinning: no samples to thin");
  if (!first.empty() && target <= first.size())
    throw Error("pose thinning: a target of " + std::to_string(target) + " poses does not grow the " +
                std::to_string(first.size()) + " already kept");
  if (target >= n) return thinPoses(samples, 0.f, SIZE_MAX, first);

  const auto axes = principalAxes(samples);
  // Upper bound: at twice the largest distance from sample 0, one pose covers everything.
  double hi = 0;
  for (size_t i = 1; i < n; ++i) {
    double d2 = 0;
    for (int k = 0; k < samples.dim; ++k) {
      const double d = double(samples.row(i)[k]) - samples.row(0)[k];
      d2 += d * d;
    }
    hi = std::max(hi, d2);
  }
  hi = 2.0 * std::sqrt(hi) + 1e-6;
  double lo = hi * 1e-6;  // a stand-in for 0 that keeps the search in log space
  const double slack = std::max(options.relativeSlack * double(target), 0.0);
  // A pass at a too-small tolerance is abandoned once it keeps far more than asked.
  const size_t cap = std::max<size_t>(target * 4, target + 16);
  double countLo = double(cap), countHi = double(std::max<size_t>(1, first.size()));  // counts at lo (at least), hi

  ThinningResult best = thinPass(samples, float(hi), cap, axes, first);
  int passes = 1;
  auto miss = [&](const ThinningResult& r) {
    return r.truncated ? double(n) : std::abs(double(r.kept.size()) - double(target));
  };
  for (int it = 0; it < options.maxIterations; ++it) {
    // The count falls roughly like a power of the tolerance: interpolate in log-log between the
    // bracket's ends, kept away from them so that the bracket always shrinks; plain log-space
    // bisection while the low end's count is unknown (truncated).
    const double llo = std::log(lo), lhi = std::log(hi);
    double f = 0.5;
    if (countLo > double(target) && countHi < double(target) && countLo < double(cap))
      f = (std::log(countLo) - std::log(double(target))) / (std::log(countLo) - std::log(countHi));
    f = std::clamp(f, 0.1, 0.9);
    const double mid = std::exp(llo + f * (lhi - llo));
    ThinningResult r = thinPass(samples, float(mid), cap, axes, first);
    ++passes;
    const bool tooMany = r.truncated || r.kept.size() > target;
    if (miss(r) < miss(best) || (miss(r) == miss(best) && r.tolerance > best.tolerance)) best = r;
    if (miss(best) <= slack && !best.truncated) break;
    if (tooMany) {
      lo = mid;
      countLo = r.truncated ? double(cap) : double(r.kept.size());
    } else {
      hi = mid;
      countHi = double(r.kept.size());
    }
    if (hi - lo <= 1e-7 * hi) break;
  }
  best.passes = passes;
  return best;
}

}  // namespace swish::bake
