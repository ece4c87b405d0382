// AVX2+FMA MLP kernels: the contract of mlp_kernel.hpp on 8 float lanes.
//
// Every function that uses AVX2 carries SWISH_AVX2 (a target attribute) instead of the file being built
// with -mavx2: the rest of the program stays runnable on any x86-64, and no inline function shared with
// other translation units gets compiled for AVX2 here (which a #pragma GCC target could cause).
//
// Register tiling of a dense layer: a tile is 2 instances x 32 outputs (4 vectors of 8). That is 8
// independent accumulator chains, enough to hide the FMA latency (4 cycles, 2 per cycle), while the 4
// weight vectors loaded per input are shared by both instances.
#include "swish/runtime/mlp_kernel.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#include <cfloat>
#include <cstdint>

#include "swish/runtime/fast_exp.hpp"

#define SWISH_AVX2 __attribute__((target("avx2,fma")))

namespace swish::runtime {

namespace {

// The vector twin of expApprox (fast_exp.hpp). _mm256_max_ps/_mm256_min_ps return their SECOND operand
// when either is NaN: the constant goes first so that NaN passes through.
SWISH_AVX2 inline __m256 exp8(__m256 x) {
  using namespace fast_exp_detail;
  x = _mm256_max_ps(_mm256_set1_ps(kMinX), x);
  x = _mm256_min_ps(_mm256_set1_ps(kMaxX), x);
  const __m256 nf =
      _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(kLog2e)), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m256 r = _mm256_fnmadd_ps(nf, _mm256_set1_ps(kLn2Hi), x);
  r = _mm256_fnmadd_ps(nf, _mm256_set1_ps(kLn2Lo), r);
  __m256 p = _mm256_set1_ps(kP0);
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(kP1));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(kP2));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(kP3));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(kP4));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(kP5));
  p = _mm256_fmadd_ps(p, _mm256_mul_ps(r, r), _mm256_add_ps(r, _mm256_set1_ps(1.f)));
  // NaN converts to INT_MIN: the exponent bits below are then garbage, but p is NaN already.
  const __m256i n = _mm256_cvtps_epi32(nf);
  const __m256i n1 = _mm256_srai_epi32(n, 1);
  const __m256i n2 = _mm256_sub_epi32(n, n1);
  const __m256i bias = _mm256_set1_epi32(127);
  const __m256 s1 = _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(n1, bias), 23));
  const __m256 s2 = _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(n2, bias), 23));
  return _mm256_mul_ps(_mm256_mul_ps(p, s1), s2);
}

SWISH_AVX2 inline __m256 selu8(__m256 x) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 e = exp8(_mm256_min_ps(zero, x));  // exp only of the negative part: NaN stays NaN
  const __m256 la = _mm256_set1_ps(kSeluLambda * kSeluAlpha);
  const __m256 neg = _mm256_fmsub_ps(e, la, la);
  const __m256 pos = _mm256_mul_ps(x, _mm256_set1_ps(kSeluLambda));
  return _mm256_blendv_ps(neg, pos, _mm256_cmp_ps(x, zero, _CMP_GT_OQ));  // NaN > 0 is false: NaN branch
}

// Bias + SELU + clamp for hidden layers, or de-normalisation + clamp for the output layer, of the 8
// outputs starting at column col.
SWISH_AVX2 inline void storeEpilogue(const PackedDenseLayer& L, __m256 acc, float* out, int col) {
  if (L.selu) {
    _mm256_storeu_ps(out + col, _mm256_min_ps(_mm256_set1_ps(L.activationLimit), selu8(acc)));
  } else {
    const __m256 y = _mm256_fmadd_ps(acc, _mm256_loadu_ps(L.outScale + col), _mm256_loadu_ps(L.outMean + col));
    _mm256_storeu_ps(out + col, _mm256_max_ps(_mm256_set1_ps(-FLT_MAX), _mm256_min_ps(_mm256_set1_ps(FLT_MAX), y)));
  }
}

// NI (1 or 2) instances x 32 outputs. Accumulators are named variables rather than an array: GCC keeps
// an array of __m256 on the stack and stores it back every iteration.
template <int NI>
SWISH_AVX2 inline void tile32(const PackedDenseLayer& L, const float* in, size_t inStride, float* out, size_t outStride,
                              int col0) {
  const float* b = L.bias + col0;
  __m256 a0 = _mm256_loadu_ps(b), a1 = _mm256_loadu_ps(b + 8), a2 = _mm256_loadu_ps(b + 16),
         a3 = _mm256_loadu_ps(b + 24);
  __m256 c0 = a0, c1 = a1, c2 = a2, c3 = a3;
  const float* w = L.weightsT + col0;
  const size_t wStride = size_t(L.outputsPadded);
  const float* x0 = in;
  const float* x1 = in + inStride;
  const int inputs = L.inputs;  // a local: the stores below could alias L, so GCC would reload it
  for (int k = 0; k < inputs; ++k, w += wStride) {
    const __m256 w0 = _mm256_loadu_ps(w), w1 = _mm256_loadu_ps(w + 8), w2 = _mm256_loadu_ps(w + 16),
                 w3 = _mm256_loadu_ps(w + 24);
    const __m256 s = _mm256_broadcast_ss(x0 + k);
    a0 = _mm256_fmadd_ps(s, w0, a0);
    a1 = _mm256_fmadd_ps(s, w1, a1);
    a2 = _mm256_fmadd_ps(s, w2, a2);
    a3 = _mm256_fmadd_ps(s, w3, a3);
    if constexpr (NI == 2) {
      const __m256 t = _mm256_broadcast_ss(x1 + k);
      c0 = _mm256_fmadd_ps(t, w0, c0);
      c1 = _mm256_fmadd_ps(t, w1, c1);
      c2 = _mm256_fmadd_ps(t, w2, c2);
      c3 = _mm256_fmadd_ps(t, w3, c3);
    }
  }
  storeEpilogue(L, a0, out, col0);
  storeEpilogue(L, a1, out, col0 + 8);
  storeEpilogue(L, a2, out, col0 + 16);
  storeEpilogue(L, a3, out, col0 + 24);
  if constexpr (NI == 2) {
    storeEpilogue(L, c0, out + outStride, col0);
    storeEpilogue(L, c1, out + outStride, col0 + 8);
    storeEpilogue(L, c2, out + outStride, col0 + 16);
    storeEpilogue(L, c3, out + outStride, col0 + 24);
  }
}

// NI instances x 8 outputs: the remainder of widths that are not multiples of 32. Fewer independent
// chains (latency-bound), acceptable off the paper's shapes.
template <int NI>
SWISH_AVX2 inline void tile8(const PackedDenseLayer& L, const float* in, size_t inStride, float* out, size_t outStride,
                             int col0) {
  __m256 a = _mm256_loadu_ps(L.bias + col0), c = a;
  const float* w = L.weightsT + col0;
  const size_t wStride = size_t(L.outputsPadded);
  for (int k = 0; k < L.inputs; ++k, w += wStride) {
    const __m256 wv = _mm256_loadu_ps(w);
    a = _mm256_fmadd_ps(_mm256_broadcast_ss(in + k), wv, a);
    if constexpr (NI == 2) c = _mm256_fmadd_ps(_mm256_broadcast_ss(in + inStride + k), wv, c);
  }
  storeEpilogue(L, a, out, col0);
  if constexpr (NI == 2) storeEpilogue(L, c, out + outStride, col0);
}

template <int NI>
SWISH_AVX2 inline void tileRow(const PackedDenseLayer& L, const float* in, size_t inStride, float* out,
                               size_t outStride) {
  int c = 0;
  for (; c + 32 <= L.outputsPadded; c += 32) tile32<NI>(L, in, inStride, out, outStride, c);
  for (; c < L.outputsPadded; c += 8) tile8<NI>(L, in, inStride, out, outStride, c);
}

}  // namespace

SWISH_AVX2 void denseLayerAvx2(const PackedDenseLayer& L, const float* in, size_t inStride, size_t count, float* out,
                               size_t outStride) {
  size_t i = 0;
  for (; i + 2 <= count; i += 2) tileRow<2>(L, in + i * inStride, inStride, out + i * outStride, outStride);
  if (i < count) tileRow<1>(L, in + i * inStride, inStride, out + i * outStride, outStride);
}

SWISH_AVX2 void normaliseInputAvx2(const PackedInputNormalisation& n, const float* x, size_t count, float* out,
                                   size_t outStride) {
  const int size = n.size;
  const int full = size / 8 * 8;
  // Lanes [0, size - full) of the tail are read; the rest are neither read nor trusted (written as 0).
  alignas(32) int32_t maskBits[8];
  for (int l = 0; l < 8; ++l) maskBits[l] = l < size - full ? -1 : 0;
  const __m256i tailMask = _mm256_load_si256(reinterpret_cast<const __m256i*>(maskBits));
  const __m256 hi = _mm256_set1_ps(n.limit), lo = _mm256_set1_ps(-n.limit);
  for (size_t i = 0; i < count; ++i) {
    const float* xi = x + i * size_t(size);
    float* oi = out + i * outStride;
    for (int k = 0; k < full; k += 8) {
      const __m256 v = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(xi + k), _mm256_loadu_ps(n.mean + k)),
                                     _mm256_loadu_ps(n.invScale + k));
      _mm256_storeu_ps(oi + k, _mm256_max_ps(lo, _mm256_min_ps(hi, v)));
    }
    if (full < size) {
      const __m256 v =
          _mm256_mul_ps(_mm256_sub_ps(_mm256_maskload_ps(xi + full, tailMask), _mm256_loadu_ps(n.mean + full)),
                        _mm256_loadu_ps(n.invScale + full));
      _mm256_storeu_ps(oi + full,
                       _mm256_and_ps(_mm256_castsi256_ps(tailMask), _mm256_max_ps(lo, _mm256_min_ps(hi, v))));
    }
  }
}

SWISH_AVX2 void expArrayAvx2(const float* x, float* out, size_t n) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) _mm256_storeu_ps(out + i, exp8(_mm256_loadu_ps(x + i)));
  if (i < n) {
    alignas(32) float buf[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (size_t k = i; k < n; ++k) buf[k - i] = x[k];
    _mm256_store_ps(buf, exp8(_mm256_load_ps(buf)));
    for (size_t k = i; k < n; ++k) out[k] = buf[k - i];
  }
}

bool cpuHasAvx2Fma() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

}  // namespace swish::runtime

#else  // not x86: the portable kernels are the only ones.

#include "swish/core/error.hpp"

namespace swish::runtime {
bool cpuHasAvx2Fma() { return false; }
void denseLayerAvx2(const PackedDenseLayer&, const float*, size_t, size_t, float*, size_t) {
  throw Error("mlp: the AVX2 kernel does not exist on this architecture");
}
void normaliseInputAvx2(const PackedInputNormalisation&, const float*, size_t, float*, size_t) {
  throw Error("mlp: the AVX2 kernel does not exist on this architecture");
}
void expArrayAvx2(const float*, float*, size_t) {
  throw Error("mlp: the AVX2 kernel does not exist on this architecture");
}
}  // namespace swish::runtime

#endif
