#include "swish/bake/cloth/cloth_constraints.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include "swish/core/error.hpp"

namespace swish::bake {

ClothConstraints buildClothConstraints(const SimulationMesh& mesh, const Points3f& x, const ClothMaterial& mat) {
  validateClothMaterial(mat);
  const size_t nv = size_t(x.rows()), nt = size_t(mesh.triangles.rows());
  ClothConstraints c;
  std::vector<double> area(nt, 0.0);
  c.vertexArea.assign(nv, 0.f);
  for (size_t t = 0; t < nt; ++t) {
    const Vec3f p0 = x.row(mesh.triangles(t, 0)), p1 = x.row(mesh.triangles(t, 1)), p2 = x.row(mesh.triangles(t, 2));
    area[t] = 0.5 * double((p1 - p0).cross(p2 - p0).norm());
    for (int k = 0; k < 3; ++k) c.vertexArea[mesh.triangles(t, k)] += float(area[t] / 3.0);
  }
  c.inverseMass.resize(nv);
  for (size_t v = 0; v < nv; ++v) {
    if (!(c.vertexArea[v] > 0.f))
      throw Error("simulation mesh: vertex " + std::to_string(v) + " lies on no triangle of positive area");
    c.inverseMass[v] = 1.f / (mat.density * c.vertexArea[v]);
  }

  // Edges with their (up to two) triangles and the vertex opposite the edge in each.
  struct EdgeInfo {
    uint32_t a, b;
    int32_t opposite[2] = {-1, -1};
    double area = 0.0;  // sum of the adjacent triangles' areas
  };
  std::vector<EdgeInfo> edges;
  std::unordered_map<uint64_t, uint32_t> index;
  index.reserve(nt * 2);
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.triangles(t, k), b = mesh.triangles(t, (k + 1) % 3);
      const uint32_t o = mesh.triangles(t, (k + 2) % 3);
      if (a > b) std::swap(a, b);
      auto [it, inserted] = index.try_emplace((uint64_t(a) << 32) | b, uint32_t(edges.size()));
      if (inserted) edges.push_back({a, b});
      EdgeInfo& e = edges[it->second];
      e.opposite[e.opposite[0] < 0 ? 0 : 1] = int32_t(o);
      e.area += area[t];
    }

  for (const EdgeInfo& e : edges) {
    const float rest = (x.row(e.a) - x.row(e.b)).norm();
    if (!(rest > 0.f)) continue;  // welded duplicates cannot be constrained by a length
    // Each triangle's area is shared by its three edges.
    const double a = e.area / 3.0;
    c.stretch.push_back(
        {e.a, e.b, rest, float(1.0 / (mat.stretchModulus * a)), float(1.0 / (mat.compressionModulus * a))});
    if (e.opposite[1] < 0) continue;
    const uint32_t o0 = uint32_t(e.opposite[0]), o1 = uint32_t(e.opposite[1]);
    const float across = (x.row(o0) - x.row(o1)).norm();
    if (!(across > 0.f)) continue;
    // Folding the hinge by theta moves the cross distance by about theta * h (h: mean height of the
    // two triangles over the edge), and a discrete shell stores k_b * theta^2 * |e| / h (Grinspun et
    // al. 2003, up to a constant). In strain form C = dd / across that is this compliance.
    const double h = e.area / double(rest);
    const float compliance =
        float(h * h * h / (double(mat.bendingStiffness) * double(rest) * double(across) * double(across)));
    c.bending.push_back({o0, o1, across, compliance, compliance});
  }

  for (size_t t = 0; t < nt; ++t) {
    const uint32_t v0 = mesh.triangles(t, 0), v1 = mesh.triangles(t, 1), v2 = mesh.triangles(t, 2);
    const Vec3f e1 = x.row(v1) - x.row(v0), e2 = x.row(v2) - x.row(v0);
    const Vec3f n = e1.cross(e2);
    if (!(n.norm() > 0.f)) continue;
    const Vec3f nn = n.normalized();
    Vec3f warp = Vec3f::UnitY() - nn * nn.y();
    if (warp.norm() < 0.3f) warp = Vec3f::UnitX() - nn * nn.x();  // a near-horizontal triangle
    warp.normalize();
    const Vec3f weft = warp.cross(nn);
    Eigen::Matrix2f dm;
    dm << e1.dot(weft), e2.dot(weft), e1.dot(warp), e2.dot(warp);
    if (!(std::abs(dm.determinant()) > 0.f)) continue;
    const Eigen::Matrix2f inv = dm.inverse();
    c.shear.push_back(
        {{v0, v1, v2}, inv(0, 0), inv(0, 1), inv(1, 0), inv(1, 1), float(1.0 / (mat.shearModulus * area[t]))});
  }
  return c;
}

std::vector<Tether> buildTethers(const SimulationMesh& mesh, const Points3f& x, const std::vector<uint32_t>& attached) {
  const size_t nv = size_t(x.rows());
  const std::vector<std::vector<uint32_t>> neighbours = buildVertexNeighbours(mesh.triangles, nv);
  std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
  std::vector<uint32_t> anchor(nv, UINT32_MAX);
  using Item = std::pair<double, uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (uint32_t a : attached) {
    dist[a] = 0.0;
    anchor[a] = a;
    queue.push({0.0, a});
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (uint32_t n : neighbours[v]) {
      const double nd = d + double((x.row(v) - x.row(n)).norm());
      if (nd < dist[n] || (nd == dist[n] && anchor[v] < anchor[n])) {
        dist[n] = nd;
        anchor[n] = anchor[v];
        queue.push({nd, n});
      }
    }
  }
  std::vector<Tether> tethers;
  for (uint32_t v = 0; v < nv; ++v)
    if (anchor[v] != UINT32_MAX && anchor[v] != v) tethers.push_back({v, anchor[v], float(dist[v])});
  return tethers;
}

}  // namespace swish::bake
