#include "swish/bake/transfer/laplacian_smoothing.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

struct WeldedGraph {
  std::vector<uint32_t> welded, representatives;
  // Per undirected welded edge (a < b): summed cotangent weight and number of incident triangles.
  std::map<std::pair<uint32_t, uint32_t>, std::pair<double, int>> edges;
};

WeldedGraph buildGraph(const Triangles& tris, const Points3f& rest) {
  WeldedGraph g;
  const std::vector<uint32_t> weld = weldByPosition(rest);  // smallest index at the same position
  g.welded.assign(weld.size(), 0);
  std::vector<uint32_t> idOfRep(weld.size(), UINT32_MAX);
  for (size_t v = 0; v < weld.size(); ++v) {
    const uint32_t r = weld[v];
    if (idOfRep[r] == UINT32_MAX) {
      idOfRep[r] = uint32_t(g.representatives.size());
      g.representatives.push_back(r);
    }
    g.welded[v] = idOfRep[r];
  }
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = tris(t, k), j = tris(t, (k + 1) % 3), o = tris(t, (k + 2) % 3);
      const uint32_t a = g.welded[i], b = g.welded[j];
      if (a == b) continue;
      // Cotangent of the angle opposite edge (i, j) in this triangle.
      const Vec3d pi = rest.row(i).transpose().cast<double>(), pj = rest.row(j).transpose().cast<double>();
      const Vec3d po = rest.row(o).transpose().cast<double>();
      const Vec3d e1 = pi - po, e2 = pj - po;
      const double s = e1.cross(e2).norm();
      const double cot = s > 1e-30 ? e1.dot(e2) / s : 0.0;
      auto& e = g.edges[{std::min(a, b), std::max(a, b)}];
      e.first += 0.5 * cot;
      e.second += 1;
    }
  }
  return g;
}

}  // namespace

LaplacianSmoother::LaplacianSmoother(const Triangles& tris, const Points3f& rest, const LaplacianSmoothingSettings& s,
                                     const std::string& what)
    : settings_(s), what_(what), vertexCount_(size_t(rest.rows())) {
  if (!(s.strength >= 0.f && s.strength <= 1.f))
    throw Error(what + ": strength " + std::to_string(s.strength) + " is outside [0, 1]");
  if (s.iterations < 0 || s.iterations > 100000)
    throw Error(what + ": iterations " + std::to_string(s.iterations) + " is outside [0, 100000]");
  if (!rest.allFinite()) throw Error(what + ": non-finite rest positions");
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (tris(t, k) >= vertexCount_) throw Error(what + ": triangle " + std::to_string(t) + " index out of range");

  WeldedGraph g = buildGraph(tris, rest);
  welded_ = std::move(g.welded);
  representatives_ = std::move(g.representatives);
  const size_t n = representatives_.size();

  // Boundary vertices: on an edge used by exactly one triangle. They keep only boundary neighbours.
  std::vector<char> onBoundary(n, 0);
  for (const auto& [e, w] : g.edges)
    if (w.second == 1) onBoundary[e.first] = onBoundary[e.second] = 1;

  std::vector<std::vector<std::pair<uint32_t, float>>> adj(n);
  for (const auto& [e, w] : g.edges) {
    const bool boundaryEdge = w.second == 1;
    const float uniform = 1.f;
    const float cot = float(std::max(0.0, w.first));
    for (int side = 0; side < 2; ++side) {
      const uint32_t a = side ? e.second : e.first, b = side ? e.first : e.second;
      if (onBoundary[a] && !boundaryEdge) continue;  // boundary vertices follow the boundary curve
      // Boundary curves use uniform weights: cotangents of a one-sided edge say little about the curve.
      const float weight = (settings_.weights == LaplacianWeights::Cotangent && !onBoundary[a]) ? cot : uniform;
      adj[a].push_back({b, weight});
    }
  }
  // Corners of a boundary (the boundary turns by more than 45 degrees there in the rest shape: the
  // corner of a slit or a square hem) are features: smoothing them would round them off every pose.
  for (size_t v = 0; v < n; ++v) {
    if (!onBoundary[v] || adj[v].size() != 2) continue;
    const Vec3f p = rest.row(representatives_[v]).transpose();
    const Vec3f a = (p - Vec3f(rest.row(representatives_[adj[v][0].first]).transpose())).normalized();
    const Vec3f b = (Vec3f(rest.row(representatives_[adj[v][1].first]).transpose()) - p).normalized();
    if (a.dot(b) < std::cos(float(M_PI) / 4.f)) adj[v].clear();
  }
  offsets_.assign(n + 1, 0);
  for (size_t v = 0; v < n; ++v) {
    float sum = 0.f;
    for (const auto& nb : adj[v]) sum += nb.second;
    // All-zero cotangent weights (degenerate fan): fall back to uniform for this vertex.
    const bool uniform = !(sum > 1e-12f);
    if (uniform) sum = float(adj[v].size());
    for (const auto& nb : adj[v]) {
      neighbours_.push_back(nb.first);
      weights_.push_back(uniform ? 1.f / sum : nb.second / sum);
    }
    offsets_[v + 1] = uint32_t(neighbours_.size());
  }
}

Points3f LaplacianSmoother::smooth(const Points3f& positions) const {
  if (size_t(positions.rows()) != vertexCount_)
    throw Error(what_ + ": " + std::to_string(positions.rows()) + " positions for a mesh of " +
                std::to_string(vertexCount_) + " vertices");
  const size_t n = representatives_.size();
  // Start from the representative of each welded vertex (seam copies of a transferred mesh can differ
  // slightly when they were bound to different simulation triangles: average them instead).
  std::vector<Vec3d> x(n, Vec3d::Zero()), next(n);
  std::vector<int> count(n, 0);
  for (size_t v = 0; v < vertexCount_; ++v) {
    x[welded_[v]] += positions.row(Eigen::Index(v)).transpose().cast<double>();
    ++count[welded_[v]];
  }
  for (size_t w = 0; w < n; ++w) x[w] /= double(count[w]);
  const double lambda = settings_.strength;
  for (int it = 0; it < settings_.iterations && lambda > 0.0; ++it) {
    for (size_t v = 0; v < n; ++v) {
      if (offsets_[v] == offsets_[v + 1]) {
        next[v] = x[v];
        continue;
      }
      Vec3d mean = Vec3d::Zero();
      for (uint32_t k = offsets_[v]; k < offsets_[v + 1]; ++k) mean += double(weights_[k]) * x[neighbours_[k]];
      next[v] = x[v] + lambda * (mean - x[v]);
    }
    std::swap(x, next);
  }
  Points3f out(Eigen::Index(vertexCount_), 3);
  for (size_t v = 0; v < vertexCount_; ++v) out.row(Eigen::Index(v)) = x[welded_[v]].cast<float>().transpose();
  return out;
}

Points3f LaplacianSmoother::smoothDisplacement(const Points3f& positions, const Points3f& reference) const {
  if (reference.rows() != positions.rows())
    throw Error(what_ + ": reference has " + std::to_string(reference.rows()) + " vertices, positions " +
                std::to_string(positions.rows()));
  // The reference's seam copies coincide (skinned copies share position and weights), so adding it back
  // keeps the copies together.
  return reference + smooth(positions - reference);
}

float umbrellaRoughness(const Points3f& positions, const Triangles& triangles) {
  LaplacianSmoothingSettings s;
  s.weights = LaplacianWeights::Uniform;
  s.iterations = 1;
  s.strength = 1.f;
  // One full umbrella step moves each vertex exactly by its Laplacian.
  const LaplacianSmoother smoother(triangles, positions, s, "roughness");
  const Points3f moved = smoother.smooth(positions);
  double sum = 0.0;
  for (Eigen::Index v = 0; v < positions.rows(); ++v) sum += (moved.row(v) - positions.row(v)).squaredNorm();
  return positions.rows() ? float(std::sqrt(sum / double(positions.rows()))) : 0.f;
}

}  // namespace swish::bake
