#pragma once
// Linear blend skinning and its inverse (to pre-skinning space, Kry et al. 2002). Shared by the bake
// (which un-skins simulated shapes before PCA) and the runtime CPU reference (which skins them back).
#include "swish/core/mesh.hpp"

namespace swish {

// Sum_k w_k * M_{j_k} for one vertex.
Mat4f blendedSkinMatrix(const SkinWeights& skin, size_t vertex, const std::vector<Mat4f>& skinMatrices);

// Skins pre-skinning-space positions (N x 3) with the given matrices.
Points3f skinPositions(const Points3f& preSkin, const SkinWeights& skin, const std::vector<Mat4f>& skinMatrices);

// Inverse: character-space positions -> pre-skinning space, by inverting each vertex's blended
// matrix. Throws Error if a blended matrix is singular (a vertex whose weights cancel a rotation).
Points3f unskinPositions(const Points3f& posed, const SkinWeights& skin, const std::vector<Mat4f>& skinMatrices);

}  // namespace swish
