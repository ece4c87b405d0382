#pragma once
// Filling the texels of a baked map that no UV chart covers, so that bilinear filtering at chart
// borders and the smaller mip levels never blend in garbage. Ring by ring, each empty texel with at
// least one filled 8-neighbour takes the mean of those neighbours (as they were before the ring
// started, so the result does not depend on scan order). After the last ring, what is still empty
// gets the flat value (X = Y = 0). Deterministic.
#include <cstdint>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

struct DilationResult {
  size_t dilated = 0;    // texels filled from neighbours
  size_t setToFlat = 0;  // texels still empty after the last ring, set to (0, 0)
};

// filled: width * height flags (non-zero = holds a baked value); updated to all ones.
DilationResult dilateNormalMap(NormalMapImage& image, std::vector<uint8_t>& filled, int rings);

}  // namespace swish::bake
