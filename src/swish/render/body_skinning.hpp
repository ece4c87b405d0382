#pragma once
// The mannequin body of the preview, skinned on the CPU each frame with the model's skinning matrices
// (api::Model::skinningMatrices: world space). A body is a few thousand vertices and is drawn once per
// frame, so the CPU is plenty, and it keeps the preview a plain host of the public API.
#include <cstddef>
#include <vector>

#include "swish/api_types.hpp"

namespace swish::render {

struct BodyMesh;

class BodySkinner {
 public:
  // Copies the body (validated by the caller) and computes rest normals when it has none.
  explicit BodySkinner(const BodyMesh& body);
  size_t vertexCount() const { return rest_.size() / 3; }
  // Writes positions (3 floats per vertex) then normals (3 per vertex) to `out` (6 * vertexCount floats).
  void skin(const std::vector<api::Mat4>& skinMatrices, float* out) const;

 private:
  std::vector<float> rest_, restNormals_, weights_;
  std::vector<uint16_t> joints_;
  uint32_t influences_;
};

// Area-weighted vertex normals of a triangle mesh (3 floats per vertex).
std::vector<float> vertexNormals(const std::vector<float>& positions, const std::vector<uint32_t>& triangles);

}  // namespace swish::render
