#pragma once
// Normal-map lookup (paper section 2.2, "for lookup we simply use a brute force search for the nearest
// code"): the database map whose PCA key is nearest, in Euclidean distance, to the normal code the MLP
// predicted.
//
// Keys are laid out at construction dimension-major in blocks of 8 maps, so the search is, per code
// dimension, one subtraction and one multiply-add per 8 keys (AVX2 when the CPU has it, portable C++
// otherwise; both compute the same float operations in the same order per key, so they agree bitwise
// except for FMA rounding). Distances are exact squared differences, not |k|^2 - 2 k.c + |c|^2 (which
// cancels badly for codes near a key far from the origin).
//
// Ties (equal squared distances, e.g. duplicate keys) go to the lowest map index: deterministic.
// A code with a NaN or Inf component has no nearest key: the search returns found = false and the
// caller's fallback index (FrameEvaluator passes the character's previous selection, 0 on its first
// frame), never an arbitrary index. A finite code so far away that float distances overflow is searched
// again in double precision, so it still gets its true nearest key.
#include <cstdint>
#include <span>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/runtime/mlp_evaluator.hpp"

namespace swish::runtime {

struct NearestCode {
  uint32_t index = 0;           // the selected map (the fallback when !found)
  float distanceSquared = 0.f;  // to the selected key; NaN when !found
  bool found = false;           // false: the code was not finite
};

class NearestCodeSearch {
 public:
  // keys: mapCount x codeDims, row m = map m's key. Throws Error when there are no maps, no dimensions,
  // or non-finite keys.
  explicit NearestCodeSearch(const MatXf& keys, CpuKernel kernel = CpuKernel::Auto);

  uint32_t mapCount() const { return mapCount_; }
  uint32_t codeDims() const { return codeDims_; }
  CpuKernel kernel() const { return kernel_; }

  // code holds codeDims() floats; fallback is returned (with found = false) for a non-finite code.
  NearestCode find(std::span<const float> code, uint32_t fallback = 0) const;

 private:
  NearestCode findDouble(std::span<const float> code) const;

  uint32_t mapCount_ = 0, codeDims_ = 0, blocks_ = 0;  // blocks of 8 maps
  CpuKernel kernel_ = CpuKernel::Portable;
  std::vector<float> packed_;  // dimension-major: row d = dimension d of every key, padded to 8 lanes
  MatXf keys_;                 // the original keys, for the double-precision fallback
};

}  // namespace swish::runtime
