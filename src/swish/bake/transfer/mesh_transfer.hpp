#pragma once
// Binding the low-resolution game mesh to the high-resolution simulation mesh (paper 2.2,
// "Postprocessing": the in-game mesh follows corresponding locations on the simulated mesh).
//
// In the rest pose each game vertex finds its closest point on the simulation surface: a triangle and
// barycentrics, plus the remaining offset expressed in the local frame of the surface there (interpolated
// vertex normal, the triangle's first edge made perpendicular to it, and their cross product). In a
// simulated pose the same surface point and frame are rebuilt from the posed simulation mesh and the
// offset re-applied, so a game vertex that floats 2 mm above the cloth still floats 2 mm above it after
// the cloth rotates. With identical meshes every offset is zero and the transfer is exact.
#include <string>
#include <vector>

#include "swish/core/mesh_frames.hpp"

namespace swish::bake {

struct GameVertexBinding {
  uint32_t triangle = 0;              // simulation triangle
  float u = 0.f, v = 0.f;             // barycentrics of its corners 1 and 2
  Vec3f localOffset = Vec3f::Zero();  // (tangent, bitangent, normal) components of game - surface point
};

class MeshTransfer {
 public:
  // simRest/simTriangles: the simulation mesh in the rest pose; gameRest: the game mesh's rest positions.
  // Throws Error naming `what` for empty or inconsistent meshes.
  MeshTransfer(const Points3f& simRest, const Triangles& simTriangles, const Points3f& gameRest,
               const std::string& what = "mesh transfer");

  // Game-mesh positions that follow the simulation mesh in a pose (same vertex count and order as
  // simRest). Throws Error if the count differs or positions are not finite.
  Points3f follow(const Points3f& simPosed) const;

  const std::vector<GameVertexBinding>& bindings() const { return bindings_; }
  // Largest rest-pose distance from a game vertex to the simulation surface (a sanity figure: a large
  // value means the meshes do not overlap where they should).
  float maxBindingDistance() const { return maxBindingDistance_; }
  size_t simulationVertexCount() const { return simVertexCount_; }

 private:
  Triangles simTriangles_;
  MeshFrameTopology simTopology_;  // welded normals of the simulation mesh
  std::vector<GameVertexBinding> bindings_;
  float maxBindingDistance_ = 0.f;
  size_t simVertexCount_ = 0;
  std::string what_;
};

// Area-weighted vertex normals of a mesh, seam copies welded by rest position (the same normals
// computeVertexFrames produces). Used for the simulation mesh by the transfer and by the baker.
Points3f surfaceVertexNormals(const Points3f& positions, const Triangles& triangles, const MeshFrameTopology& topology);

}  // namespace swish::bake
