#pragma once
// The skinned body as a collider for the cloth: closest point and signed distance to its triangle
// surface. Signs come from angle-weighted pseudo-normals (Baerentzen & Aanaes 2005), which are exact
// for closed manifold meshes whatever feature (face, edge, vertex) is closest. Triangles are binned in
// a uniform grid rebuilt at every pose; queries visit only the cells that overlap their search ball.
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"

namespace swish::bake {

class BodyCollider {
 public:
  struct Hit {
    bool found = false;          // false: no surface within the search distance
    float signedDistance = 0.f;  // > 0 outside the body, < 0 inside
    Vec3f point = Vec3f::Zero();   // closest point on the surface
    Vec3f normal = Vec3f::Zero();  // unit, pointing out of the body at `point`
  };

  // `body`: rest positions, triangles, skin weights (validated, naming `what`). `cellSize`: grid
  // spacing in metres, best about the usual search distance.
  BodyCollider(const Mesh& body, float cellSize, const std::string& what = "body");

  // Poses the body by linear blend skinning and rebuilds normals and the grid.
  void pose(const std::vector<Mat4f>& skinMatrices);
  // Places the body at explicit positions (same vertex count) and rebuilds: for analytic test shapes.
  void setPositions(const Points3f& positions);

  // Closest surface point to p within maxDistance (metres). Thread-safe (const, no scratch state).
  Hit closest(const Vec3f& p, float maxDistance) const;

  const Points3f& positions() const { return positions_; }
  size_t triangleCount() const { return size_t(triangles_.rows()); }

 private:
  void rebuild();

  Points3f restPositions_;
  Triangles triangles_;
  SkinWeights skin_;
  std::vector<uint32_t> triangleEdges_;  // 3 per triangle: edge index of sides ab, bc, ca
  std::vector<std::array<int32_t, 2>> edgeTriangles_;  // up to two triangles per edge (-1: none)
  float cellSize_;

  Points3f positions_;
  std::vector<Vec3f> faceNormals_, vertexNormals_, edgeNormals_;
  std::vector<Vec4f> triangleSpheres_;  // centre + radius: a cheap reject before the exact test
  Vec3f gridOrigin_ = Vec3f::Zero();
  Eigen::Vector3i gridDims_ = Eigen::Vector3i::Zero();
  std::vector<uint32_t> cellStart_, cellTriangles_;  // compressed rows: cell -> triangles
};

}  // namespace swish::bake
