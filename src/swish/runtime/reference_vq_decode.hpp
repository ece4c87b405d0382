#pragma once
// CPU reference of shaders/vq_decode.comp: one database map decoded to its snorm8 X, Y texels (the
// layout documented on NormalMapDatabase in model/model.hpp). Decoding is a lossless gather, so the GPU
// must match it exactly. An index >= codebookSize (impossible in a validated model) decodes to 0, 0.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "swish/model/model.hpp"

namespace swish::runtime {

struct DecodedNormalMap {
  uint32_t width = 0, height = 0;
  std::vector<int8_t> xy;  // (y * width + x) * 2 + {0: X, 1: Y}, snorm8
};

DecodedNormalMap referenceVqDecode(const NormalMapDatabase& db, uint32_t map);

// snorm8 -> float as Vulkan defines it: max(c / 127, -1).
inline float snorm8ToFloat(int8_t c) { return std::max(float(c) / 127.f, -1.f); }

}  // namespace swish::runtime
