#pragma once
// The distance kernels of NearestCodeSearch. packed is dimension-major: row d holds dimension d of
// every key, padded to paddedMaps (a multiple of 8) lanes. dist[m] = sum_d (code[d] - key_m[d])^2 for
// m in [0, paddedMaps), accumulated over d in increasing order.
#include <cstddef>
#include <cstdint>

namespace swish::runtime {

void squaredDistancesPortable(const float* packed, size_t paddedMaps, uint32_t dims, const float* code, float* dist);
// Only callable when cpuHasAvx2Fma() is true.
void squaredDistancesAvx2(const float* packed, size_t paddedMaps, uint32_t dims, const float* code, float* dist);
// Lowest index of the smallest of dist[0, paddedMaps) (no NaN allowed; paddedMaps a multiple of 8, > 0).
uint32_t firstMinIndexAvx2(const float* dist, size_t paddedMaps);

}  // namespace swish::runtime
