#pragma once
// A polynomial exp for float and the SELU activation built on it, shared by the MLP kernels.
//
// Why not std::exp: it does not vectorise, and the network spends a third of its time in SELU. This is
// Cephes' expf: n = round(x / ln 2), r = x - n ln 2 (Cody-Waite, two constants), a degree-7 polynomial for
// e^r on |r| <= ln2/2, then scaling by 2^n. The scaling is done as two multiplications by 2^(n/2) so that
// the whole float range comes out right, overflow to +inf and gradual underflow to subnormals and 0
// included, without masks. NaN in gives NaN out. Accuracy: within 2 ulp of the correctly rounded result
// for normal results (tests/unit/test_runtime_mlp.cpp measures it against std::exp); subnormal results are
// within 1 subnormal step.
//
// The AVX2 kernel (mlp_kernel_avx2.cpp) implements exactly this algorithm on 8 lanes (with FMA in the
// range reduction and the polynomial); this scalar version is the portable path.
#include <bit>
#include <cstdint>

namespace swish::runtime {

inline constexpr float kSeluLambda = 1.0507009873554805f;
inline constexpr float kSeluAlpha = 1.6732632423543772f;

namespace fast_exp_detail {
inline constexpr float kLog2e = 1.44269504088896341f;
inline constexpr float kLn2Hi = 0.693359375f;     // few significant bits: n * kLn2Hi is exact
inline constexpr float kLn2Lo = -2.12194440e-4f;  // ln 2 - kLn2Hi
inline constexpr float kMinX = -104.f;            // below: the result rounds to 0
inline constexpr float kMaxX = 89.f;              // above: the result overflows to +inf
inline constexpr float kP0 = 1.9875691500e-4f, kP1 = 1.3981999507e-3f, kP2 = 8.3334519073e-3f, kP3 = 4.1665795894e-2f,
                       kP4 = 1.6666665459e-1f, kP5 = 5.0000001201e-1f;
inline float pow2i(int32_t e) { return std::bit_cast<float>(uint32_t(e + 127) << 23); }  // e in [-126, 127]
}  // namespace fast_exp_detail

inline float expApprox(float x) {
  using namespace fast_exp_detail;
  if (!(x == x)) return x;  // NaN: also keeps the float -> int conversion below defined
  x = x < kMinX ? kMinX : (x > kMaxX ? kMaxX : x);
  // Round to nearest by the 1.5 * 2^23 trick (exact for |t| < 2^22), which vectorises without SSE4.1.
  const float t = x * kLog2e;
  const float nf = (t + 12582912.f) - 12582912.f;
  const float r = (x - nf * kLn2Hi) - nf * kLn2Lo;
  float p = kP0;
  p = p * r + kP1;
  p = p * r + kP2;
  p = p * r + kP3;
  p = p * r + kP4;
  p = p * r + kP5;
  p = p * r * r + r + 1.f;
  const int32_t n = int32_t(nf);
  const int32_t n1 = n >> 1;  // floor(n / 2): both halves stay within the normal exponent range
  return p * pow2i(n1) * pow2i(n - n1);
}

// SELU(x) = lambda * x for x > 0, lambda * alpha * (exp(x) - 1) otherwise. NaN propagates.
inline float seluApprox(float x) {
  if (x > 0.f) return kSeluLambda * x;
  return kSeluLambda * kSeluAlpha * (expApprox(x) - 1.f);
}

}  // namespace swish::runtime
