#include "swish/bake/pose_thinning.hpp"

#include <algorithm>
#include <cmath>

#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {
namespace {

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

std::vector<float> randomUnitDirection(int dim, uint64_t seed) {
  Rng rng(seed);
  std::vector<float> dir(static_cast<size_t>(dim));
  double n = 0;
  for (auto& v : dir) {
    v = float(rng.normal());
    n += double(v) * v;
  }
  n = std::sqrt(n);
  for (auto& v : dir) v = float(v / n);
  return dir;
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

// The kept set: rows copied contiguously, plus their projections sorted for the band search.
class KeptPoses {
 public:
  KeptPoses(int dim, std::vector<float> direction) : dim_(dim), dir_(std::move(direction)) {}

  float project(const float* x) const {
    float p = 0.f;
    for (int k = 0; k < dim_; ++k) p += x[k] * dir_[size_t(k)];
    return p;
  }
  size_t size() const { return sampleIndex_.size(); }
  const float* row(size_t k) const { return rows_.data() + k * size_t(dim_); }
  uint32_t sampleIndex(size_t k) const { return sampleIndex_[k]; }

  // Index of some kept pose within sqrt(limitSq) of x (projection p), or -1.
  long findWithin(const float* x, float p, float tol, float limitSq, size_t& checks) const {
    auto lo = std::lower_bound(order_.begin(), order_.end(), p - tol,
                               [](const Entry& e, float v) { return e.proj < v; });
    for (auto it = lo; it != order_.end() && it->proj <= p + tol; ++it) {
      ++checks;
      if (withinSquared(x, row(it->slot), dim_, limitSq)) return long(it->slot);
    }
    return -1;
  }

  void add(const float* x, float p, uint32_t sample) {
    const size_t slot = size();
    rows_.insert(rows_.end(), x, x + dim_);
    sampleIndex_.push_back(sample);
    Entry e{p, uint32_t(slot)};
    order_.insert(std::upper_bound(order_.begin(), order_.end(), e,
                                   [](const Entry& a, const Entry& b) { return a.proj < b.proj; }),
                  e);
  }

 private:
  struct Entry {
    float proj;
    uint32_t slot;
  };
  int dim_;
  std::vector<float> dir_;
  std::vector<float> rows_;
  std::vector<uint32_t> sampleIndex_;
  std::vector<Entry> order_;
};

}  // namespace

ThinningResult thinPoses(const PoseSamples& samples, float tolerance, size_t maxKept, uint64_t seed) {
  checkSamples(samples);
  if (!(tolerance >= 0.f) || !std::isfinite(tolerance))
    throw Error("pose thinning: tolerance " + std::to_string(tolerance) + " must be finite and >= 0");
  const int dim = samples.dim;
  const size_t n = samples.size();
  // "Farther than the tolerance" keeps a pose; distance <= tolerance rejects it.
  const float limitSq = tolerance * tolerance;
  KeptPoses kept(dim, randomUnitDirection(dim, seed));
  ThinningResult result;
  result.tolerance = tolerance;
  long lastCover = -1;
  for (size_t i = 0; i < n; ++i) {
    const float* x = samples.row(i);
    if (lastCover >= 0) {
      ++result.distanceChecks;
      if (withinSquared(x, kept.row(size_t(lastCover)), dim, limitSq)) continue;
    }
    const float p = kept.project(x);
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

ThinningResult thinPosesToCount(const PoseSamples& samples, size_t target, const ThinToCountOptions& options) {
  checkSamples(samples);
  const size_t n = samples.size();
  if (target == 0) throw Error("pose thinning: target count must be at least 1");
  if (n == 0) throw Error("pose thinning: no samples to thin");
  if (target >= n) return thinPoses(samples, 0.f, SIZE_MAX, options.seed);

  // Upper bound: at twice the largest distance from sample 0, one pose covers everything.
  double hi = 0;
  for (size_t i = 1; i < n; ++i) {
    double s = 0;
    for (int k = 0; k < samples.dim; ++k) {
      const double d = double(samples.row(i)[k]) - samples.row(0)[k];
      s += d * d;
    }
    hi = std::max(hi, s);
  }
  hi = 2.0 * std::sqrt(hi) + 1e-6;
  double lo = 0.0;
  const double slack = std::max(options.relativeSlack * double(target), 0.0);
  // A pass at a too-small tolerance is abandoned once it keeps far more than asked.
  const size_t cap = std::max<size_t>(target * 4, target + 16);

  ThinningResult best = thinPoses(samples, float(hi), cap, options.seed);
  auto distance = [&](const ThinningResult& r) {
    return r.truncated ? double(n) : std::abs(double(r.kept.size()) - double(target));
  };
  for (int it = 0; it < options.maxIterations; ++it) {
    const double mid = 0.5 * (lo + hi);
    ThinningResult r = thinPoses(samples, float(mid), cap, options.seed);
    const bool tooMany = r.truncated || r.kept.size() > target;
    if (distance(r) < distance(best) || (distance(r) == distance(best) && !r.truncated && r.tolerance > best.tolerance))
      best = r;
    if (distance(best) <= slack && !best.truncated) break;
    if (tooMany) lo = mid;
    else hi = mid;
    if (hi - lo <= 1e-7 * hi) break;
  }
  return best;
}

}  // namespace swish::bake
