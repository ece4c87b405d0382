#include "swish/runtime/nearest_code.hpp"

#include <cfloat>
#include <cmath>
#include <limits>
#include <string>

#include "swish/core/error.hpp"
#include "swish/runtime/mlp_kernel.hpp"
#include "swish/runtime/nearest_code_kernel.hpp"

namespace swish::runtime {

namespace {
size_t padded8(size_t n) { return (n + 7) & ~size_t(7); }
constexpr size_t kStackMaps = 1024;  // distances of databases up to this size live on the stack
}  // namespace

void squaredDistancesPortable(const float* packed, size_t paddedMaps, uint32_t dims, const float* code, float* dist) {
  for (size_t m = 0; m < paddedMaps; ++m) dist[m] = 0.f;
  const float* row = packed;
  for (uint32_t d = 0; d < dims; ++d, row += paddedMaps) {
    const float c = code[d];
    for (size_t m = 0; m < paddedMaps; ++m) {
      const float diff = c - row[m];
      dist[m] += diff * diff;
    }
  }
}

NearestCodeSearch::NearestCodeSearch(const MatXf& keys, CpuKernel kernel) : keys_(keys) {
  if (keys.rows() == 0) throw Error("nearest code: the normal-map database has no maps");
  if (keys.cols() == 0) throw Error("nearest code: the normal-map database keys have no dimensions");
  if (!keys.allFinite()) throw Error("nearest code: the normal-map database keys have non-finite values");
  kernel_ = resolveCpuKernel(kernel, "nearest code");
  mapCount_ = uint32_t(keys.rows());
  codeDims_ = uint32_t(keys.cols());
  const size_t pad = padded8(mapCount_);
  blocks_ = uint32_t(pad / 8);
  // Padding lanes hold zeros; their distances are overwritten with +inf before the argmin.
  packed_.assign(pad * codeDims_, 0.f);
  for (uint32_t d = 0; d < codeDims_; ++d)
    for (uint32_t m = 0; m < mapCount_; ++m) packed_[d * pad + m] = keys(m, d);
}

NearestCode NearestCodeSearch::find(std::span<const float> code, uint32_t fallback) const {
  if (code.size() != codeDims_)
    throw Error("nearest code: code has " + std::to_string(code.size()) + " values, the database keys " +
                std::to_string(codeDims_));
  for (float c : code)
    if (!std::isfinite(c)) return {fallback, std::numeric_limits<float>::quiet_NaN(), false};

  const size_t pad = size_t(blocks_) * 8;
  alignas(32) float stackDist[kStackMaps];
  std::vector<float> heapDist;
  float* dist = stackDist;
  if (pad > kStackMaps) {
    heapDist.resize(pad);
    dist = heapDist.data();
  }
  if (kernel_ == CpuKernel::Avx2Fma)
    squaredDistancesAvx2(packed_.data(), pad, codeDims_, code.data(), dist);
  else
    squaredDistancesPortable(packed_.data(), pad, codeDims_, code.data(), dist);
  for (size_t m = mapCount_; m < pad; ++m) dist[m] = std::numeric_limits<float>::infinity();

  // Lowest index of the smallest distance (distances are never NaN here: code and keys are finite).
  uint32_t best = 0;
  if (kernel_ == CpuKernel::Avx2Fma) {
    best = firstMinIndexAvx2(dist, pad);
  } else {
    for (uint32_t m = 1; m < mapCount_; ++m)
      if (dist[m] < dist[best]) best = m;  // strict: the first of equal distances stays
  }
  const float bestDist = dist[best];
  if (!(bestDist <= FLT_MAX)) return findDouble(code);  // every float distance overflowed
  return {best, bestDist, true};
}

NearestCode NearestCodeSearch::findDouble(std::span<const float> code) const {
  uint32_t best = 0;
  double bestDist = std::numeric_limits<double>::infinity();
  for (uint32_t m = 0; m < mapCount_; ++m) {
    double s = 0.0;
    for (uint32_t d = 0; d < codeDims_; ++d) {
      const double diff = double(code[d]) - double(keys_(m, d));
      s += diff * diff;
    }
    if (s < bestDist) {
      bestDist = s;
      best = m;
    }
  }
  return {best, float(bestDist), true};  // float(bestDist) is +inf: the distance itself is not representable
}

}  // namespace swish::runtime
