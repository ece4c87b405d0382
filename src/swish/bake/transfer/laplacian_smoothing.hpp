#pragma once
// Laplacian smoothing of the transferred game mesh (paper 2.2: "Trying to represent the deformations of
// a high-resolution mesh with a low-resolution proxy has obvious sampling frequency problems that
// present as jagged triangle quality in the in-game mesh. To tame this artifact we apply low-pass
// filtering using Laplacian mesh smoothing.")
//
// Explicit iterations x <- x + strength * (weighted mean of neighbours - x) on the mesh welded by rest
// position: seam-split copies are one vertex here, move together and end bit-identical. Boundary
// vertices (hems, collar, sleeve openings) are smoothed along the boundary only, so an open edge is not
// pulled inwards across the surface; boundary corners (the boundary turns by more than 45 degrees in
// the rest shape) stay put. Weights are uniform or cotangent (from the rest shape, clamped at
// zero so that obtuse triangles cannot make a weight negative), fixed for every pose.
//
// smoothDisplacement filters the difference to a smooth reference (the game mesh skinned to the pose)
// instead of absolute positions: the jaggedness lives in that difference, and filtering it does not
// shrink the garment the way smoothing absolute positions does.
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"

namespace swish::bake {

enum class LaplacianWeights { Uniform, Cotangent };

struct LaplacianSmoothingSettings {
  float strength = 0.5f;  // 0..1 per iteration; 0 disables
  int iterations = 8;     // >= 0
  LaplacianWeights weights = LaplacianWeights::Cotangent;
};

class LaplacianSmoother {
 public:
  // restPositions: for the weld map and the cotangent weights. Throws Error for bad settings or meshes.
  LaplacianSmoother(const Triangles& triangles, const Points3f& restPositions,
                    const LaplacianSmoothingSettings& settings, const std::string& what = "Laplacian smoothing");

  Points3f smooth(const Points3f& positions) const;
  // reference + smooth(positions - reference), see above.
  Points3f smoothDisplacement(const Points3f& positions, const Points3f& reference) const;

  size_t weldedVertexCount() const { return representatives_.size(); }
  const LaplacianSmoothingSettings& settings() const { return settings_; }

 private:
  LaplacianSmoothingSettings settings_;
  std::string what_;
  size_t vertexCount_ = 0;
  std::vector<uint32_t> welded_;           // vertex -> welded index
  std::vector<uint32_t> representatives_;  // welded index -> one original vertex
  // Neighbours of each welded vertex with normalised weights (CSR).
  std::vector<uint32_t> offsets_, neighbours_;
  std::vector<float> weights_;
};

// A jaggedness figure used by tests and reports: root mean square length of the uniform (umbrella)
// Laplacian over interior welded vertices.
float umbrellaRoughness(const Points3f& positions, const Triangles& triangles);

}  // namespace swish::bake
