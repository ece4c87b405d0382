// The AVX2 kernels of the scheduled constraint sweep (constraint_schedule.hpp): eight constraints of one
// dependency level per register, each lane doing projectDistance's or projectShear's float operations
// in their order, so that the result is bitwise the scalar one. No fused multiply-add anywhere: the
// functions carry target("avx2") only (the rest of the program is built without FMA too, so the scalar
// projections are never contracted either), and sums of three follow Eigen's x0 + (x1 + x2).
//
// As in mlp_kernel_avx2.cpp, a target attribute on each function instead of -mavx2 on the file: the
// program stays runnable on any x86-64 and no inline function shared with other files is built for AVX2.
#include "swish/bake/cloth/constraint_schedule.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#define SWISH_AVX2 __attribute__((target("avx2")))

namespace swish::bake::detail {
namespace {

struct Lane3 {
  __m256 x, y, z;
};

SWISH_AVX2 inline Lane3 gather3(const float* p, __m256i offset) {
  return {_mm256_i32gather_ps(p, offset, 4), _mm256_i32gather_ps(p + 1, offset, 4),
          _mm256_i32gather_ps(p + 2, offset, 4)};
}

SWISH_AVX2 inline void scatter3(float* p, const int32_t* offset, const Lane3& v) {
  alignas(32) float x[8], y[8], z[8];
  _mm256_store_ps(x, v.x);
  _mm256_store_ps(y, v.y);
  _mm256_store_ps(z, v.z);
  for (int k = 0; k < 8; ++k) {
    float* q = p + offset[k];
    q[0] = x[k];
    q[1] = y[k];
    q[2] = z[k];
  }
}

// |v|^2 as Eigen sums a 3-vector's squares: x^2 + (y^2 + z^2).
SWISH_AVX2 inline __m256 squaredNorm(const Lane3& v) {
  return _mm256_add_ps(_mm256_mul_ps(v.x, v.x), _mm256_add_ps(_mm256_mul_ps(v.y, v.y), _mm256_mul_ps(v.z, v.z)));
}

SWISH_AVX2 inline Lane3 sub(const Lane3& a, const Lane3& b) {
  return {_mm256_sub_ps(a.x, b.x), _mm256_sub_ps(a.y, b.y), _mm256_sub_ps(a.z, b.z)};
}
SWISH_AVX2 inline Lane3 scale(const Lane3& a, __m256 s) {
  return {_mm256_mul_ps(a.x, s), _mm256_mul_ps(a.y, s), _mm256_mul_ps(a.z, s)};
}
// s * a + t * b, each coefficient as Eigen evaluates `s * a + t * b`: (s * a_k) + (t * b_k).
SWISH_AVX2 inline Lane3 combine(__m256 s, const Lane3& a, __m256 t, const Lane3& b) {
  return {_mm256_add_ps(_mm256_mul_ps(s, a.x), _mm256_mul_ps(t, b.x)),
          _mm256_add_ps(_mm256_mul_ps(s, a.y), _mm256_mul_ps(t, b.y)),
          _mm256_add_ps(_mm256_mul_ps(s, a.z), _mm256_mul_ps(t, b.z))};
}
// a + s * d (sign +1) or a - s * d (sign -1), where s * d is a scalar times a 3-vector.
SWISH_AVX2 inline Lane3 addScaled(const Lane3& a, __m256 s, const Lane3& d) {
  return {_mm256_add_ps(a.x, _mm256_mul_ps(s, d.x)), _mm256_add_ps(a.y, _mm256_mul_ps(s, d.y)),
          _mm256_add_ps(a.z, _mm256_mul_ps(s, d.z))};
}
SWISH_AVX2 inline Lane3 subScaled(const Lane3& a, __m256 s, const Lane3& d) {
  return {_mm256_sub_ps(a.x, _mm256_mul_ps(s, d.x)), _mm256_sub_ps(a.y, _mm256_mul_ps(s, d.y)),
          _mm256_sub_ps(a.z, _mm256_mul_ps(s, d.z))};
}
SWISH_AVX2 inline Lane3 select(const Lane3& whenFalse, const Lane3& whenTrue, __m256 mask) {
  return {_mm256_blendv_ps(whenFalse.x, whenTrue.x, mask), _mm256_blendv_ps(whenFalse.y, whenTrue.y, mask),
          _mm256_blendv_ps(whenFalse.z, whenTrue.z, mask)};
}
SWISH_AVX2 inline __m256 negate(__m256 v) { return _mm256_xor_ps(v, _mm256_set1_ps(-0.f)); }

}  // namespace

// projectDistance (cloth_constraints.hpp), eight lanes.
SWISH_AVX2 void sweepDistanceAvx2(const DistanceSchedule& s, size_t begin, size_t end, float* x, float invDt2,
                                  float* lambda) {
  const __m256 zero = _mm256_setzero_ps(), tiny = _mm256_set1_ps(1e-9f), idt2 = _mm256_set1_ps(invDt2);
  for (size_t k = begin; k < end; k += 8) {
    const __m256i oi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s.i3.data() + k));
    const __m256i oj = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s.j3.data() + k));
    const Lane3 xi = gather3(x, oi), xj = gather3(x, oj);
    const Lane3 d = sub(xi, xj);
    const __m256 len = _mm256_sqrt_ps(squaredNorm(d));
    const __m256 valid = _mm256_cmp_ps(len, tiny, _CMP_GT_OQ);  // !(len > 1e-9): left as it is
    const __m256 rest = _mm256_loadu_ps(s.rest.data() + k);
    const __m256 strain = _mm256_div_ps(_mm256_sub_ps(len, rest), rest);
    const __m256 tension = _mm256_cmp_ps(strain, zero, _CMP_GT_OQ);
    const __m256 lam0 = _mm256_loadu_ps(lambda + k);
    // A multiplier of the other branch's sign starts afresh (projectDistance).
    const __m256 reset = _mm256_or_ps(_mm256_and_ps(tension, _mm256_cmp_ps(lam0, zero, _CMP_GT_OQ)),
                                      _mm256_andnot_ps(tension, _mm256_cmp_ps(lam0, zero, _CMP_LT_OQ)));
    const __m256 lam = _mm256_andnot_ps(reset, lam0);
    const __m256 compliance = _mm256_blendv_ps(_mm256_loadu_ps(s.compressionCompliance.data() + k),
                                               _mm256_loadu_ps(s.tensionCompliance.data() + k), tension);
    const __m256 alpha = _mm256_mul_ps(compliance, idt2);
    const __m256 wsum = _mm256_loadu_ps(s.wsum.data() + k);
    const __m256 dl =
        _mm256_div_ps(_mm256_sub_ps(negate(strain), _mm256_mul_ps(alpha, lam)), _mm256_add_ps(wsum, alpha));
    _mm256_storeu_ps(lambda + k, _mm256_blendv_ps(lam0, _mm256_add_ps(lam, dl), valid));
    const Lane3 g = scale(d, _mm256_div_ps(dl, _mm256_mul_ps(len, rest)));
    const Lane3 ni = select(xi, addScaled(xi, _mm256_loadu_ps(s.wi.data() + k), g), valid);
    const Lane3 nj = select(xj, subScaled(xj, _mm256_loadu_ps(s.wj.data() + k), g), valid);
    scatter3(x, s.i3.data() + k, ni);
    scatter3(x, s.j3.data() + k, nj);
  }
}

// projectShear (cloth_constraints.hpp), eight lanes.
SWISH_AVX2 void sweepShearAvx2(const ShearSchedule& s, size_t begin, size_t end, float* x, float invDt2,
                               float* lambda) {
  const __m256 tiny = _mm256_set1_ps(1e-20f), idt2 = _mm256_set1_ps(invDt2);
  for (size_t k = begin; k < end; k += 8) {
    __m256i o[3];
    Lane3 p[3];
    __m256 w[3];
    for (int n = 0; n < 3; ++n) {
      o[n] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s.v3[n].data() + k));
      p[n] = gather3(x, o[n]);
      w[n] = _mm256_loadu_ps(s.w[n].data() + k);
    }
    const __m256 a = _mm256_loadu_ps(s.a.data() + k), b = _mm256_loadu_ps(s.b.data() + k),
                 c = _mm256_loadu_ps(s.c.data() + k), d = _mm256_loadu_ps(s.d.data() + k);
    const Lane3 e1 = sub(p[1], p[0]), e2 = sub(p[2], p[0]);
    const Lane3 f0 = combine(a, e1, c, e2), f1 = combine(b, e1, d, e2);
    const __m256 C =
        _mm256_add_ps(_mm256_mul_ps(f0.x, f1.x), _mm256_add_ps(_mm256_mul_ps(f0.y, f1.y), _mm256_mul_ps(f0.z, f1.z)));
    const Lane3 g1 = combine(a, f1, b, f0), g2 = combine(c, f1, d, f0);
    const Lane3 g0 = {negate(_mm256_add_ps(g1.x, g2.x)), negate(_mm256_add_ps(g1.y, g2.y)),
                      negate(_mm256_add_ps(g1.z, g2.z))};
    const __m256 wsum =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w[0], squaredNorm(g0)), _mm256_mul_ps(w[1], squaredNorm(g1))),
                      _mm256_mul_ps(w[2], squaredNorm(g2)));
    const __m256 valid = _mm256_cmp_ps(wsum, tiny, _CMP_GT_OQ);
    const __m256 alpha = _mm256_mul_ps(_mm256_loadu_ps(s.compliance.data() + k), idt2);
    const __m256 lam = _mm256_loadu_ps(lambda + k);
    const __m256 dl = _mm256_div_ps(_mm256_sub_ps(negate(C), _mm256_mul_ps(alpha, lam)), _mm256_add_ps(wsum, alpha));
    _mm256_storeu_ps(lambda + k, _mm256_blendv_ps(lam, _mm256_add_ps(lam, dl), valid));
    const Lane3* g[3] = {&g0, &g1, &g2};
    for (int n = 0; n < 3; ++n)
      scatter3(x, s.v3[n].data() + k, select(p[n], addScaled(p[n], _mm256_mul_ps(w[n], dl), *g[n]), valid));
  }
}

bool avx2Available() { return __builtin_cpu_supports("avx2"); }

}  // namespace swish::bake::detail

#else

namespace swish::bake::detail {
void sweepDistanceAvx2(const DistanceSchedule&, size_t, size_t, float*, float, float*) {}
void sweepShearAvx2(const ShearSchedule&, size_t, size_t, float*, float, float*) {}
bool avx2Available() { return false; }
}  // namespace swish::bake::detail

#endif
