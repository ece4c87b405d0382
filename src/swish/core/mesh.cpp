#include "swish/core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include "swish/core/error.hpp"

namespace swish {

void Mesh::validate(const std::string& what, size_t jointCount) const {
  const size_t n = vertexCount();
  if (n == 0) throw Error(what + ": mesh has no vertices");
  if (!positions.allFinite()) throw Error(what + ": mesh has non-finite vertex positions");
  if (normals.rows() != 0 && size_t(normals.rows()) != n)
    throw Error(what + ": " + std::to_string(normals.rows()) + " normals for " + std::to_string(n) + " vertices");
  if (tangents.rows() != 0 && size_t(tangents.rows()) != n)
    throw Error(what + ": " + std::to_string(tangents.rows()) + " tangents for " + std::to_string(n) + " vertices");
  if (uvs.rows() != 0 && size_t(uvs.rows()) != n)
    throw Error(what + ": " + std::to_string(uvs.rows()) + " UVs for " + std::to_string(n) + " vertices");
  if (uvs.rows() != 0 && !uvs.allFinite()) throw Error(what + ": mesh has non-finite UVs");
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (triangles(t, k) >= n)
        throw Error(what + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(triangles(t, k)) +
                    " but the mesh has " + std::to_string(n) + " vertices");
  if (!skin.weights.empty() || !skin.joints.empty()) {
    if (skin.influences < 1 || skin.influences > kMaxInfluences)
      throw Error(what + ": " + std::to_string(skin.influences) + " influences per vertex (1.." +
                  std::to_string(kMaxInfluences) + " supported)");
    const size_t need = n * size_t(skin.influences);
    if (skin.weights.size() != need || skin.joints.size() != need)
      throw Error(what + ": skin has " + std::to_string(skin.weights.size()) + " weights and " +
                  std::to_string(skin.joints.size()) + " joint indices, expected " + std::to_string(need));
    for (size_t v = 0; v < n; ++v) {
      double sum = 0;
      for (int k = 0; k < skin.influences; ++k) {
        const float w = skin.weights[v * skin.influences + k];
        if (!std::isfinite(w) || w < 0.f)
          throw Error(what + ": vertex " + std::to_string(v) + " has an invalid skin weight");
        if (jointCount && skin.joints[v * skin.influences + k] >= jointCount)
          throw Error(what + ": vertex " + std::to_string(v) + " is weighted to joint " +
                      std::to_string(skin.joints[v * skin.influences + k]) + " of " + std::to_string(jointCount));
        sum += w;
      }
      if (std::abs(sum - 1.0) > 1e-3)
        throw Error(what + ": skin weights of vertex " + std::to_string(v) + " sum to " + std::to_string(sum) +
                    ", not 1");
    }
  }
}

std::vector<uint32_t> weldByPosition(const Points3f& p) {
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> first;
  std::vector<uint32_t> weld(size_t(p.rows()));
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    uint32_t b[3];
    for (int k = 0; k < 3; ++k) {
      float f = p(i, k) == 0.f ? 0.f : p(i, k);  // -0 == +0
      std::memcpy(&b[k], &f, 4);
    }
    auto [it, inserted] = first.try_emplace({b[0], b[1], b[2]}, uint32_t(i));
    weld[size_t(i)] = it->second;
  }
  return weld;
}

Triangles trianglesWeldedByPosition(const Points3f& positions, const Triangles& triangles) {
  const std::vector<uint32_t> weld = weldByPosition(positions);
  Triangles out = triangles;
  for (Eigen::Index t = 0; t < out.rows(); ++t)
    for (int k = 0; k < 3; ++k) out(t, k) = weld[out(t, k)];
  return out;
}

std::vector<std::pair<uint32_t, uint32_t>> openEdges(const Triangles& triangles) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = triangles(t, k), j = triangles(t, (k + 1) % 3);
      ++uses[{std::min(i, j), std::max(i, j)}];
    }
  std::vector<std::pair<uint32_t, uint32_t>> open;
  for (const auto& [edge, n] : uses)
    if (n == 1) open.push_back(edge);
  return open;
}

std::vector<std::vector<uint32_t>> buildVertexNeighbours(const Triangles& tris, size_t n,
                                                         const std::vector<uint32_t>* weld) {
  auto rep = [&](uint32_t v) { return weld ? (*weld)[v] : v; };
  std::vector<std::vector<uint32_t>> neighbours(n);
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = rep(tris(t, k)), b = rep(tris(t, (k + 1) % 3));
      neighbours[a].push_back(b);
      neighbours[b].push_back(a);
    }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

std::vector<std::pair<uint32_t, uint32_t>> uniqueEdges(const std::vector<std::vector<uint32_t>>& neighbours) {
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (uint32_t a = 0; a < uint32_t(neighbours.size()); ++a)
    for (const uint32_t b : neighbours[a])
      if (b > a) edges.emplace_back(a, b);
  return edges;
}

std::vector<float> edgeLengths(const Points3f& positions, const std::vector<std::pair<uint32_t, uint32_t>>& edges) {
  std::vector<float> lengths;
  lengths.reserve(edges.size());
  for (const auto& [a, b] : edges) lengths.push_back((positions.row(a) - positions.row(b)).norm());
  return lengths;
}

std::vector<uint32_t> connectedParts(const Triangles& tris, size_t n) {
  // Union-find; a union hangs the larger root under the smaller, so every root is its part's minimum.
  std::vector<uint32_t> parent(n);
  for (uint32_t v = 0; v < n; ++v) parent[v] = v;
  auto find = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 1; k < 3; ++k) {
      const uint32_t a = find(tris(t, 0)), b = find(tris(t, k));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  for (uint32_t v = 0; v < n; ++v) parent[v] = find(v);
  return parent;
}

VertexTriangleAdjacency buildVertexTriangleAdjacency(const Triangles& tris, size_t n,
                                                     const std::vector<uint32_t>* weld) {
  // Count per representative, then expand to every vertex of the group.
  auto rep = [&](uint32_t v) { return weld ? (*weld)[v] : v; };
  std::vector<std::vector<uint32_t>> perRep(n);
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      auto& list = perRep[rep(tris(t, k))];
      if (list.empty() || list.back() != uint32_t(t)) list.push_back(uint32_t(t));
    }
  VertexTriangleAdjacency a;
  a.offsets.resize(n + 1, 0);
  for (size_t v = 0; v < n; ++v) a.offsets[v + 1] = a.offsets[v] + uint32_t(perRep[rep(uint32_t(v))].size());
  a.triangles.reserve(a.offsets[n]);
  for (size_t v = 0; v < n; ++v) {
    const auto& l = perRep[rep(uint32_t(v))];
    a.triangles.insert(a.triangles.end(), l.begin(), l.end());
  }
  return a;
}

}  // namespace swish
