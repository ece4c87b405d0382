// Portable MLP kernels: the contract of mlp_kernel.hpp in plain C++.
#include <cfloat>

#include "swish/runtime/fast_exp.hpp"
#include "swish/runtime/mlp_kernel.hpp"

namespace swish::runtime {

namespace {
inline size_t padded8(size_t n) { return (n + 7) & ~size_t(7); }
// Comparisons written so that NaN falls through unchanged (std::min/fmin would drop or keep it by
// argument order, which is easy to get wrong).
inline float clampKeepNaN(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
}  // namespace

void normaliseInputPortable(const PackedInputNormalisation& n, const float* x, size_t count, float* out,
                            size_t outStride) {
  const size_t size = size_t(n.size), pad = padded8(size);
  for (size_t i = 0; i < count; ++i) {
    const float* xi = x + i * size;
    float* oi = out + i * outStride;
    for (size_t k = 0; k < size; ++k) oi[k] = clampKeepNaN((xi[k] - n.mean[k]) * n.invScale[k], -n.limit, n.limit);
    for (size_t k = size; k < pad; ++k) oi[k] = 0.f;
  }
}

void denseLayerPortable(const PackedDenseLayer& L, const float* in, size_t inStride, size_t count, float* out,
                        size_t outStride) {
  const size_t width = size_t(L.outputsPadded);
  for (size_t i = 0; i < count; ++i) {
    const float* a = in + i * inStride;
    float* acc = out + i * outStride;
    for (size_t o = 0; o < width; ++o) acc[o] = L.bias[o];
    const float* w = L.weightsT;
    for (int k = 0; k < L.inputs; ++k, w += width) {
      const float ak = a[k];
      for (size_t o = 0; o < width; ++o) acc[o] += ak * w[o];
    }
    if (L.selu) {
      for (size_t o = 0; o < width; ++o) {
        const float h = seluApprox(acc[o]);
        acc[o] = h > L.activationLimit ? L.activationLimit : h;  // SELU >= -1.76: only the top needs a bound
      }
    } else {
      for (size_t o = 0; o < width; ++o)
        acc[o] = clampKeepNaN(acc[o] * L.outScale[o] + L.outMean[o], -FLT_MAX, FLT_MAX);
    }
  }
}

}  // namespace swish::runtime
