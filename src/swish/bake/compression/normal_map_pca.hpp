#pragma once
// PCA of normal maps: each map (X, Y of every texel) flattened to one sample. The first C components
// give every map its code, the key of the nearest-neighbour database and the normal half of Lambda.
// A dataset holds hundreds of 360x360 maps (259,200 values each), so the PCA is randomised by default.
#include <vector>

#include "swish/bake/compression/pca.hpp"
#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

// D x N, D = 2 * width * height; throws Error if maps are empty or differ in size.
MatXf flattenNormalMaps(const std::vector<const NormalMapImage*>& maps);

struct NormalMapPca {
  PcaResult pca;
  MatXf codes;  // C x N: the code of every input map
  int codeDims() const { return int(codes.rows()); }
};

NormalMapPca fitNormalMapPca(const std::vector<const NormalMapImage*>& maps, int codeDims, uint64_t seed);

// Code of one more map under a fitted PCA (C).
VecXf normalMapCode(const PcaResult& pca, const NormalMapImage& map);

}  // namespace swish::bake
