#pragma once
// Linear blend skinning and its inverse (to pre-skinning space, Kry et al. 2002). Shared by the bake
// (which un-skins simulated shapes before PCA) and the runtime CPU reference (which skins them back).
#include "swish/core/mesh.hpp"

namespace swish {

// Sum_k w_k * M_{j_k} for one vertex.
Mat4f blendedSkinMatrix(const SkinWeights& skin, size_t vertex, const std::vector<Mat4f>& skinMatrices);

// Skins pre-skinning-space positions (N x 3) with the given matrices.
Points3f skinPositions(const Points3f& preSkin, const SkinWeights& skin, const std::vector<Mat4f>& skinMatrices);

// How far un-skinning trusts a vertex's blended matrix A (its upper 3x3). Linear blend skinning
// collapses where a vertex's joints turn far apart: two joints half-and-half, turned 180 degrees
// relative to each other, blend to a matrix with a zero singular value (the candy wrapper), and a
// shape there has no pre-skinning position. An exact inverse then throws a millimetre of posed
// shape metres away (measured on the corpus bake: a shoulder vertex of an arms-overhead pose 180 m
// from rest), and one such pose takes over the PCA basis and the network's loss. So along each
// singular direction with singular value s < minSingularValue the inverse is damped to s / floor^2
// instead of 1 / s (continuous at the floor, zero at s = 0): the displacement from the reference
// (rest) position there is amplified at most 1 / floor, never without bound. Directions at or
// above the floor are inverted exactly, so a vertex whose matrix is well conditioned gets the exact
// inverse, bitwise as before.
struct UnskinSettings {
  float minSingularValue = 0.2f;  // rigid skinning: all 1; 0.2 is two joints 157 degrees apart, half and half
};
struct UnskinStats {
  size_t dampedVertices = 0;          // vertices with a singular value below the floor
  float smallestSingularValue = 1.f;  // the smallest among them (1 when none)
};

// Inverse: character-space positions -> pre-skinning space, per vertex (posed - t) through the
// blended matrix's inverse, damped as above towards `reference` (the pre-skin positions to fall
// back on, the rest shape: same size as `posed`).
Points3f unskinPositions(const Points3f& posed, const Points3f& reference, const SkinWeights& skin,
                         const std::vector<Mat4f>& skinMatrices, const UnskinSettings& settings = {},
                         UnskinStats* stats = nullptr);

// Moves a stored shape, posed `world` with its pre-skin `preSkin` (what the run time skins), by `move` (posed
// space) at `vertices` (the other rows are untouched, bitwise). The move is un-skinned, damped as above around
// `preSkin`, and `world` moves by what that draws: where `world` is what `preSkin` draws it stays so, and where
// un-skinning had damped (a collapsed blend: `world` is a shape no pre-skin shape draws) it moves by the drawn
// move only, not to the drawable shape, which can be centimetres away. Throws Error for sizes that differ.
void moveSkinnedShape(Points3f& world, Points3f& preSkin, const Points3f& move,
                      const std::vector<Eigen::Index>& vertices, const SkinWeights& skin,
                      const std::vector<Mat4f>& skinMatrices, const UnskinSettings& settings = {});

// The vertices un-skinning would damp under these matrices (the same test), and the smallest singular
// value among them: a property of the pose and the weights, not of a shape, so a bake can count them
// for poses whose shapes it made in an earlier run.
UnskinStats collapsedSkinning(const SkinWeights& skin, const std::vector<Mat4f>& skinMatrices,
                              const UnskinSettings& settings = {});

}  // namespace swish
