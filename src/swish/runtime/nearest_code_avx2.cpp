// AVX2+FMA distances for NearestCodeSearch (contract in nearest_code_kernel.hpp). Target attributes
// rather than -mavx2 for the file, for the reason given in mlp_kernel_avx2.cpp.
#include "swish/runtime/nearest_code_kernel.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#define SWISH_AVX2 __attribute__((target("avx2,fma")))

namespace swish::runtime {

namespace {
// NB blocks of 8 keys held in registers across all dimensions: NB independent FMA chains.
template <int NB>
SWISH_AVX2 inline void blocks(const float* packed, size_t paddedMaps, uint32_t dims, const float* code, float* dist) {
  __m256 acc[8];
  for (int b = 0; b < NB; ++b) acc[b] = _mm256_setzero_ps();
  const float* row = packed;
  for (uint32_t d = 0; d < dims; ++d, row += paddedMaps) {
    const __m256 c = _mm256_broadcast_ss(code + d);
#pragma GCC unroll 8
    for (int b = 0; b < NB; ++b) {
      const __m256 diff = _mm256_sub_ps(c, _mm256_loadu_ps(row + 8 * b));
      acc[b] = _mm256_fmadd_ps(diff, diff, acc[b]);
    }
  }
  for (int b = 0; b < NB; ++b) _mm256_storeu_ps(dist + 8 * b, acc[b]);
}
}  // namespace

SWISH_AVX2 void squaredDistancesAvx2(const float* packed, size_t paddedMaps, uint32_t dims, const float* code,
                                     float* dist) {
  size_t m = 0;
  for (; m + 64 <= paddedMaps; m += 64) blocks<8>(packed + m, paddedMaps, dims, code, dist + m);
  switch ((paddedMaps - m) / 8) {
    case 7:
      blocks<7>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 6:
      blocks<6>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 5:
      blocks<5>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 4:
      blocks<4>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 3:
      blocks<3>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 2:
      blocks<2>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    case 1:
      blocks<1>(packed + m, paddedMaps, dims, code, dist + m);
      break;
    default:
      break;
  }
}

SWISH_AVX2 uint32_t firstMinIndexAvx2(const float* dist, size_t paddedMaps) {
  __m256 m = _mm256_loadu_ps(dist);
  for (size_t i = 8; i < paddedMaps; i += 8) m = _mm256_min_ps(m, _mm256_loadu_ps(dist + i));
  // Horizontal minimum, broadcast to all lanes.
  m = _mm256_min_ps(m, _mm256_permute2f128_ps(m, m, 1));
  m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
  for (size_t i = 0; i < paddedMaps; i += 8) {
    const int mask = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(dist + i), m, _CMP_EQ_OQ));
    if (mask) return uint32_t(i) + uint32_t(__builtin_ctz(unsigned(mask)));
  }
  return 0;  // unreachable for NaN-free distances
}

}  // namespace swish::runtime

#else

#include "swish/core/error.hpp"

namespace swish::runtime {
void squaredDistancesAvx2(const float*, size_t, uint32_t, const float*, float*) {
  throw Error("nearest code: the AVX2 kernel does not exist on this architecture");
}
uint32_t firstMinIndexAvx2(const float*, size_t) {
  throw Error("nearest code: the AVX2 kernel does not exist on this architecture");
}
}  // namespace swish::runtime

#endif
