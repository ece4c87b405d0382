#include "swish/core/mesh_frames.hpp"

#include <cmath>

namespace swish {

MeshFrameTopology buildFrameTopology(const Triangles& tris, const Points3f& rest) {
  const auto weld = weldByPosition(rest);
  const size_t n = size_t(rest.rows());
  return {buildVertexTriangleAdjacency(tris, n, &weld), buildVertexTriangleAdjacency(tris, n)};
}

Vec3f anyPerpendicular(const Vec3f& n) {
  const Vec3f a = n.cwiseAbs();
  Vec3f e = (a.x() <= a.y() && a.x() <= a.z()) ? Vec3f::UnitX() : (a.y() <= a.z() ? Vec3f::UnitY() : Vec3f::UnitZ());
  return n.cross(e).normalized();
}

void computeVertexFrames(const Points3f& p, const Points2f& uv, const Triangles& tris, const MeshFrameTopology& topo,
                         Points3f& normals, Points4f& tangents) {
  const Eigen::Index n = p.rows();
  normals.resize(n, 3);
  tangents.resize(n, 4);
  auto corner = [&](uint32_t t, int k) { return Vec3f(p.row(tris(t, k)).transpose()); };
  for (Eigen::Index v = 0; v < n; ++v) {
    Vec3f nsum = Vec3f::Zero();
    for (uint32_t i = topo.normalAdjacency.offsets[v]; i < topo.normalAdjacency.offsets[v + 1]; ++i) {
      const uint32_t t = topo.normalAdjacency.triangles[i];
      const Vec3f p0 = corner(t, 0);
      nsum += (corner(t, 1) - p0).cross(corner(t, 2) - p0);
    }
    const float nl = nsum.norm();
    const Vec3f nrm = nl > 0.f ? Vec3f(nsum / nl) : Vec3f::UnitZ();

    Vec3f tsum = Vec3f::Zero(), bsum = Vec3f::Zero();
    if (uv.rows() == n) {
      for (uint32_t i = topo.tangentAdjacency.offsets[v]; i < topo.tangentAdjacency.offsets[v + 1]; ++i) {
        const uint32_t t = topo.tangentAdjacency.triangles[i];
        const Vec3f p0 = corner(t, 0);
        const Vec3f e1 = corner(t, 1) - p0, e2 = corner(t, 2) - p0;
        const Vec2f uv0 = uv.row(tris(t, 0)).transpose();
        const Vec2f d1 = Vec2f(uv.row(tris(t, 1)).transpose()) - uv0;
        const Vec2f d2 = Vec2f(uv.row(tris(t, 2)).transpose()) - uv0;
        const float r = d1.x() * d2.y() - d2.x() * d1.y();
        if (r == 0.f || !std::isfinite(r)) continue;
        // Dividing by r makes a triangle's contribution independent of its UV area but keeps the
        // world-area weighting of a mirrored chart's sign.
        tsum += (e1 * d2.y() - e2 * d1.y()) / r;
        bsum += (e2 * d1.x() - e1 * d2.x()) / r;
      }
    }
    Vec3f tan = tsum - nrm * nrm.dot(tsum);
    const float tl = tan.norm();
    tan = (tl > 1e-20f && std::isfinite(tl)) ? Vec3f(tan / tl) : anyPerpendicular(nrm);
    const float w = nrm.cross(tan).dot(bsum) < 0.f ? -1.f : 1.f;
    normals.row(v) = nrm.transpose();
    tangents.row(v) << tan.x(), tan.y(), tan.z(), w;
  }
}

}  // namespace swish
