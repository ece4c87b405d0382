#include "swish/bake/transfer/mesh_transfer.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

struct LocalFrame {
  Vec3f point, tangent, bitangent, normal;
};

LocalFrame surfaceFrame(const Points3f& p, const Points3f& normals, const Triangles& tris, uint32_t t, float u,
                        float v) {
  const uint32_t i0 = tris(t, 0), i1 = tris(t, 1), i2 = tris(t, 2);
  const float w = 1.f - u - v;
  LocalFrame f;
  f.point = w * p.row(i0).transpose() + u * p.row(i1).transpose() + v * p.row(i2).transpose();
  Vec3f n = w * normals.row(i0).transpose() + u * normals.row(i1).transpose() + v * normals.row(i2).transpose();
  if (!(n.norm() > 1e-12f)) {  // opposite vertex normals cancelled: fall back to the face normal
    n = (p.row(i1) - p.row(i0)).transpose().cross((p.row(i2) - p.row(i0)).transpose());
    if (!(n.norm() > 1e-20f)) n = Vec3f::UnitZ();
  }
  f.normal = n.normalized();
  Vec3f e = (p.row(i1) - p.row(i0)).transpose();
  e -= f.normal * f.normal.dot(e);
  f.tangent = e.norm() > 1e-20f ? Vec3f(e.normalized()) : anyPerpendicular(f.normal);
  f.bitangent = f.normal.cross(f.tangent);
  return f;
}

}  // namespace

Points3f surfaceVertexNormals(const Points3f& positions, const Triangles& triangles, const MeshFrameTopology& topo) {
  Points3f normals;
  Points4f tangents;
  computeVertexFrames(positions, Points2f(), triangles, topo, normals, tangents);
  return normals;
}

MeshTransfer::MeshTransfer(const Points3f& simRest, const Triangles& simTriangles, const Points3f& gameRest,
                           const std::string& what)
    : simTriangles_(simTriangles), simVertexCount_(size_t(simRest.rows())), what_(what) {
  if (gameRest.rows() == 0) throw Error(what + ": the game mesh has no vertices");
  if (!gameRest.allFinite()) throw Error(what + ": the game mesh has non-finite rest positions");
  const TriangleRayScene scene(simRest, simTriangles, what + " (simulation mesh, rest pose)");
  simTopology_ = buildFrameTopology(simTriangles, simRest);
  const Points3f simNormals = surfaceVertexNormals(simRest, simTriangles, simTopology_);

  bindings_.resize(size_t(gameRest.rows()));
  std::vector<float> distance(bindings_.size(), 0.f);
  tbb::parallel_for(size_t(0), bindings_.size(), [&](size_t i) {
    const Vec3f g = gameRest.row(Eigen::Index(i)).transpose();
    const SurfacePoint s = scene.closestPoint(g);
    const LocalFrame f = surfaceFrame(simRest, simNormals, simTriangles_, s.triangle, s.u, s.v);
    const Vec3f d = g - f.point;
    bindings_[i] = {s.triangle, s.u, s.v, Vec3f(d.dot(f.tangent), d.dot(f.bitangent), d.dot(f.normal))};
    distance[i] = s.distance;
  });
  maxBindingDistance_ = *std::max_element(distance.begin(), distance.end());
}

Points3f MeshTransfer::follow(const Points3f& simPosed) const {
  if (size_t(simPosed.rows()) != simVertexCount_)
    throw Error(what_ + ": posed simulation mesh has " + std::to_string(simPosed.rows()) + " vertices, the bound one " +
                std::to_string(simVertexCount_));
  if (!simPosed.allFinite()) throw Error(what_ + ": posed simulation mesh has non-finite positions");
  const Points3f normals = surfaceVertexNormals(simPosed, simTriangles_, simTopology_);
  Points3f out(Eigen::Index(bindings_.size()), 3);
  tbb::parallel_for(size_t(0), bindings_.size(), [&](size_t i) {
    const GameVertexBinding& b = bindings_[i];
    const LocalFrame f = surfaceFrame(simPosed, normals, simTriangles_, b.triangle, b.u, b.v);
    const Vec3f x =
        f.point + f.tangent * b.localOffset.x() + f.bitangent * b.localOffset.y() + f.normal * b.localOffset.z();
    out.row(Eigen::Index(i)) = x.transpose();
  });
  return out;
}

}  // namespace swish::bake
