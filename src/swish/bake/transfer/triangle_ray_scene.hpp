#pragma once
// A triangle mesh in Embree, for the two geometric queries of the transfer and the normal-map bake:
// closest point on the surface (binding the game mesh to the simulation mesh) and ray casting (finding
// the simulation surface above or below a game-mesh texel). Read-only after construction and safe to
// query from many threads at once. Barycentrics follow Embree: p = (1 - u - v) p0 + u p1 + v p2.
#include <limits>
#include <memory>

#include "swish/core/types.hpp"

namespace swish::bake {

struct SurfacePoint {
  bool found = false;
  uint32_t triangle = 0;
  float u = 0.f, v = 0.f;  // barycentrics of corners 1 and 2
  Vec3f point = Vec3f::Zero();
  float distance = std::numeric_limits<float>::infinity();  // from the query point (or along the ray)
};

class TriangleRayScene {
 public:
  // Copies the geometry. Throws Error (naming `what`) for indices out of range or non-finite positions.
  TriangleRayScene(const Points3f& positions, const Triangles& triangles, const std::string& what);
  ~TriangleRayScene();
  TriangleRayScene(TriangleRayScene&&) noexcept;
  TriangleRayScene& operator=(TriangleRayScene&&) noexcept;

  // Closest surface point to p within maxRadius. Ties between equally near triangles go to the lowest
  // triangle index, so that the answer does not depend on the traversal order.
  SurfacePoint closestPoint(const Vec3f& p, float maxRadius = std::numeric_limits<float>::infinity()) const;

  // First hit of the ray origin + t * direction (direction need not be unit) with tNear <= t <= tFar.
  SurfacePoint intersect(const Vec3f& origin, const Vec3f& direction, float tNear, float tFar) const;

  const Points3f& positions() const { return positions_; }
  const Triangles& triangles() const { return triangles_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Points3f positions_;
  Triangles triangles_;
};

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5), as
// barycentrics (u, v) of b and c.
Vec2f closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c);

}  // namespace swish::bake
