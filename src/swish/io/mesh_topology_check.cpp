#include "swish/io/mesh_topology_check.hpp"

#include <algorithm>
#include <unordered_map>

#include "swish/core/error.hpp"

namespace swish::io {

TopologyReport analyseTopology(const Mesh& mesh) {
  TopologyReport r;
  const auto weld = weldByPosition(mesh.positions);
  // Directed edge (a -> b) counts, keyed by the undirected edge.
  struct EdgeUse {
    uint32_t forward = 0;   // a -> b with a < b
    uint32_t backward = 0;  // b -> a
  };
  std::unordered_map<uint64_t, EdgeUse> edges;
  edges.reserve(mesh.triangleCount() * 2);
  Vec3d centroid = Vec3d::Zero();
  size_t unique = 0;
  for (size_t v = 0; v < weld.size(); ++v)
    if (weld[v] == v) {
      centroid += mesh.positions.row(Eigen::Index(v)).transpose().cast<double>();
      ++unique;
    }
  if (unique > 0) centroid /= double(unique);

  size_t agree = 0, withNormals = 0;
  const bool hasNormals = mesh.normals.rows() == mesh.positions.rows();
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    uint32_t w[3];
    for (int k = 0; k < 3; ++k) w[k] = weld[mesh.triangles(t, k)];
    const Vec3d a = mesh.positions.row(mesh.triangles(t, 0)).transpose().cast<double>();
    const Vec3d b = mesh.positions.row(mesh.triangles(t, 1)).transpose().cast<double>();
    const Vec3d c = mesh.positions.row(mesh.triangles(t, 2)).transpose().cast<double>();
    const Vec3d n = (b - a).cross(c - a);
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2] || n.norm() <= 1e-20) {
      ++r.degenerateTriangles;
      continue;
    }
    r.signedVolume += (a - centroid).dot((b - centroid).cross(c - centroid)) / 6.0;
    if (hasNormals) {
      Vec3d vn = Vec3d::Zero();
      for (int k = 0; k < 3; ++k) vn += mesh.normals.row(mesh.triangles(t, k)).transpose().cast<double>();
      if (vn.squaredNorm() > 0) {
        ++withNormals;
        if (vn.dot(n) > 0) ++agree;
      }
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t p = w[k], q = w[(k + 1) % 3];
      const uint64_t key = (uint64_t(std::min(p, q)) << 32) | std::max(p, q);
      auto& e = edges[key];
      (p < q ? e.forward : e.backward)++;
    }
  }
  for (const auto& [key, e] : edges) {
    const uint32_t uses = e.forward + e.backward;
    if (uses == 1) ++r.boundaryEdges;
    if (uses > 2)
      ++r.nonManifoldEdges;
    else if (e.forward > 1 || e.backward > 1)
      ++r.inconsistentEdges;
  }
  r.normalAgreement = withNormals ? double(agree) / double(withNormals) : 1.0;
  return r;
}

void checkGarmentTopology(const Mesh& mesh, const std::string& what) {
  if (mesh.triangleCount() == 0) throw Error(what + ": garment has no triangles");
  const TopologyReport r = analyseTopology(mesh);
  if (r.nonManifoldEdges > 0)
    throw Error(what + ": garment is non-manifold: " + std::to_string(r.nonManifoldEdges) +
                " edges are shared by more than two triangles");
  if (r.inconsistentEdges > 0)
    throw Error(what + ": garment has flipped triangles: " + std::to_string(r.inconsistentEdges) +
                " shared edges are traversed the same way by both their triangles (inconsistent winding)");
  if (r.degenerateTriangles * 100 > mesh.triangleCount())
    throw Error(what + ": garment has " + std::to_string(r.degenerateTriangles) + " degenerate triangles of " +
                std::to_string(mesh.triangleCount()));
  if (r.signedVolume < 0.0 || r.normalAgreement < 0.5)
    throw Error(what + ": garment is inside out (triangles wound inwards: signed volume " +
                std::to_string(r.signedVolume) + " m^3, " + std::to_string(int(r.normalAgreement * 100)) +
                "% of faces agree with the stored normals)");
}

}  // namespace swish::io
