#include "swish/bake/cloth/simulation_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>
#include <set>
#include <unordered_map>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

uint64_t edgeKey(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(a) << 32) | b;
}

// Each undirected edge may border at most two triangles; more is not a surface a cloth can be.
void requireManifoldEdges(const Triangles& tris, const std::string& what) {
  std::unordered_map<uint64_t, int> uses;
  uses.reserve(size_t(tris.rows()) * 2);
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = tris(t, k), b = tris(t, (k + 1) % 3);
      if (a == b) throw Error(what + ": triangle " + std::to_string(t) + " repeats a vertex (degenerate)");
      if (++uses[edgeKey(a, b)] > 2)
        throw Error(what + ": edge " + std::to_string(std::min(a, b)) + "-" + std::to_string(std::max(a, b)) +
                    " is shared by more than two triangles (non-manifold)");
    }
}

// Averages two vertices' weights, keeps the `influences` largest (ties: lower joint index) and
// renormalises, so subdivided vertices stay valid skin data.
void blendWeights(const SkinWeights& in, uint32_t a, uint32_t b, SkinWeights& out) {
  const int n = in.influences;
  std::vector<std::pair<uint16_t, float>> merged;
  merged.reserve(size_t(2 * n));
  for (uint32_t v : {a, b})
    for (int k = 0; k < n; ++k) {
      const uint16_t j = in.joints[size_t(v) * n + k];
      const float w = 0.5f * in.weights[size_t(v) * n + k];
      if (w == 0.f) continue;
      auto it = std::find_if(merged.begin(), merged.end(), [&](auto& p) { return p.first == j; });
      if (it == merged.end())
        merged.push_back({j, w});
      else
        it->second += w;
    }
  std::sort(merged.begin(), merged.end(),
            [](auto& x, auto& y) { return x.second != y.second ? x.second > y.second : x.first < y.first; });
  if (merged.size() > size_t(n)) merged.resize(size_t(n));
  float sum = 0.f;
  for (auto& p : merged) sum += p.second;
  for (int k = 0; k < n; ++k) {
    const bool has = size_t(k) < merged.size();
    out.joints.push_back(has ? merged[size_t(k)].first : 0);
    out.weights.push_back(has ? merged[size_t(k)].second / sum : 0.f);
  }
}

}  // namespace

SimulationMesh weldedSimulationMesh(const Mesh& mesh, std::vector<uint32_t>& inputToWelded) {
  const std::vector<uint32_t> rep = weldByPosition(mesh.positions);
  inputToWelded.assign(rep.size(), 0);
  std::vector<uint32_t> repIndex(rep.size(), UINT32_MAX);
  uint32_t count = 0;
  for (size_t v = 0; v < rep.size(); ++v) {
    if (repIndex[rep[v]] == UINT32_MAX) repIndex[rep[v]] = count++;
    inputToWelded[v] = repIndex[rep[v]];
  }
  SimulationMesh s;
  s.restPositions.resize(count, 3);
  s.skin.influences = mesh.skin.influences;
  s.skin.joints.assign(size_t(count) * mesh.skin.influences, 0);
  s.skin.weights.assign(size_t(count) * mesh.skin.influences, 0.f);
  for (size_t v = 0; v < rep.size(); ++v) {
    if (rep[v] != v) continue;  // the first copy speaks for its group (copies share weights)
    const uint32_t w = inputToWelded[v];
    s.restPositions.row(w) = mesh.positions.row(Eigen::Index(v));
    for (int k = 0; k < mesh.skin.influences; ++k) {
      s.skin.joints[size_t(w) * mesh.skin.influences + k] = mesh.skin.joints[v * mesh.skin.influences + k];
      s.skin.weights[size_t(w) * mesh.skin.influences + k] = mesh.skin.weights[v * mesh.skin.influences + k];
    }
  }
  s.triangles.resize(mesh.triangles.rows(), 3);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k) s.triangles(t, k) = inputToWelded[mesh.triangles(t, k)];
  return s;
}

SimulationMesh refineToEdgeLength(const SimulationMesh& in, float maxEdge) {
  if (!std::isfinite(maxEdge) || !(maxEdge > 0.f))
    throw Error("simulation mesh refinement: the longest edge allowed must be finite and positive, got " +
                std::to_string(maxEdge));
  SimulationMesh out;
  out.gameToSim = in.gameToSim;
  out.refinedEdgeLength = maxEdge;
  out.skin = in.skin;
  const int n = in.skin.influences;
  std::vector<Vec3f> pos(in.vertexCount());
  for (size_t v = 0; v < pos.size(); ++v) pos[v] = in.restPositions.row(Eigen::Index(v));
  std::vector<std::array<uint32_t, 3>> tris(size_t(in.triangles.rows()));
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) tris[t][size_t(k)] = in.triangles(Eigen::Index(t), k);

  // Edge -> its (at most two) triangles, kept current as triangles are split.
  std::unordered_map<uint64_t, std::array<int32_t, 2>> edgeTris;
  edgeTris.reserve(tris.size() * 4);
  auto link = [&](uint32_t t) {
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] = edgeTris.try_emplace(edgeKey(tris[t][size_t(k)], tris[t][size_t((k + 1) % 3)]),
                                                 std::array<int32_t, 2>{-1, -1});
      it->second[it->second[0] < 0 ? 0 : 1] = int32_t(t);
    }
  };
  auto unlink = [&](uint32_t t) {
    for (int k = 0; k < 3; ++k) {
      auto it = edgeTris.find(edgeKey(tris[t][size_t(k)], tris[t][size_t((k + 1) % 3)]));
      for (int32_t& slot : it->second)
        if (slot == int32_t(t)) slot = -1;
      if (it->second[0] < 0 && it->second[1] < 0) edgeTris.erase(it);
    }
  };
  for (uint32_t t = 0; t < tris.size(); ++t) link(t);

  // Longest first: then the edge being split is the longest of each triangle on it (every longer
  // edge is already split, every remaining one is short enough), which is Rivara's bisection and
  // keeps the smallest angles bounded away from zero. Ties by key: deterministic.
  using Item = std::pair<float, uint64_t>;
  std::priority_queue<Item> queue;
  auto length = [&](uint64_t key) { return (pos[size_t(key >> 32)] - pos[size_t(key & 0xffffffffu)]).norm(); };
  auto consider = [&](uint32_t a, uint32_t b) {
    const uint64_t key = edgeKey(a, b);
    if (const float len = length(key); len > maxEdge) queue.push({len, key});
  };
  for (const auto& [key, t] : edgeTris) {
    (void)t;
    if (const float len = length(key); len > maxEdge) queue.push({len, key});
  }
  while (!queue.empty()) {
    const uint64_t key = queue.top().second;
    queue.pop();
    const auto found = edgeTris.find(key);
    if (found == edgeTris.end()) continue;  // split already (positions never move, so lengths are exact)
    const std::array<int32_t, 2> around = found->second;
    const uint32_t a = uint32_t(key >> 32), b = uint32_t(key & 0xffffffffu);
    const uint32_t m = uint32_t(pos.size());
    pos.push_back(0.5f * (pos[a] + pos[b]));
    SkinWeights ends;  // the two end points' weights, so blending reads nothing that grows meanwhile
    ends.influences = n;
    for (uint32_t v : {a, b})
      for (int k = 0; k < n; ++k) {
        ends.joints.push_back(out.skin.joints[size_t(v) * n + k]);
        ends.weights.push_back(out.skin.weights[size_t(v) * n + k]);
      }
    blendWeights(ends, 0, 1, out.skin);
    for (int32_t t : around) {
      if (t < 0) continue;
      const std::array<uint32_t, 3> tri = tris[size_t(t)];
      int k = 0;
      while (edgeKey(tri[size_t(k)], tri[size_t((k + 1) % 3)]) != key) ++k;
      const uint32_t x0 = tri[size_t(k)], x1 = tri[size_t((k + 1) % 3)], x2 = tri[size_t((k + 2) % 3)];
      unlink(uint32_t(t));
      tris[size_t(t)] = {x0, m, x2};  // winding kept
      tris.push_back({m, x1, x2});
      link(uint32_t(t));
      link(uint32_t(tris.size() - 1));
      consider(x0, m);
      consider(m, x1);
      consider(m, x2);
    }
  }
  out.restPositions.resize(Eigen::Index(pos.size()), 3);
  for (size_t v = 0; v < pos.size(); ++v) out.restPositions.row(Eigen::Index(v)) = pos[v];
  out.triangles.resize(Eigen::Index(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) out.triangles(Eigen::Index(t), k) = tris[t][size_t(k)];
  return out;
}

SimulationMesh collapseShortEdges(const SimulationMesh& in, float minEdge) {
  const size_t nv = in.vertexCount();
  std::vector<std::array<uint32_t, 3>> tris(size_t(in.triangles.rows()));
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) tris[t][size_t(k)] = in.triangles(Eigen::Index(t), k);
  std::vector<uint8_t> deadTri(tris.size(), 0);
  std::vector<uint32_t> mergedInto(nv);
  for (uint32_t v = 0; v < nv; ++v) mergedInto[v] = v;
  // Positions and weights change where two interior vertices merge at their midpoint.
  std::vector<Vec3f> position(nv);
  for (uint32_t v = 0; v < nv; ++v) position[v] = in.restPositions.row(v);
  SkinWeights skin = in.skin;
  const int n = in.skin.influences;
  auto pos = [&](uint32_t v) -> Vec3f { return position[v]; };

  // Passes: a collapse locks its neighbourhood for the rest of the pass (adjacency is rebuilt between
  // passes), so every decision is made on current topology.
  for (int pass = 0; pass < 32; ++pass) {
    std::vector<std::vector<uint32_t>> around(nv);  // vertex -> live triangles
    std::unordered_map<uint64_t, int> uses;
    for (uint32_t t = 0; t < tris.size(); ++t) {
      if (deadTri[t]) continue;
      for (int k = 0; k < 3; ++k) {
        around[tris[t][size_t(k)]].push_back(t);
        ++uses[edgeKey(tris[t][size_t(k)], tris[t][size_t((k + 1) % 3)])];
      }
    }
    std::vector<uint8_t> boundary(nv, 0);
    std::vector<std::pair<float, uint64_t>> shortEdges;
    for (const auto& [key, n] : uses) {
      const uint32_t a = uint32_t(key >> 32), b = uint32_t(key & 0xffffffffu);
      if (n == 1) boundary[a] = boundary[b] = 1;
      if (const float len = (pos(a) - pos(b)).norm(); len < minEdge) shortEdges.push_back({len, key});
    }
    std::sort(shortEdges.begin(), shortEdges.end());
    auto neighbours = [&](uint32_t v) {
      std::set<uint32_t> n;
      for (uint32_t t : around[v])
        for (uint32_t u : tris[t])
          if (u != v) n.insert(u);
      return n;
    };
    std::vector<uint8_t> locked(nv, 0);
    int collapsed = 0;
    for (const auto& [len, key] : shortEdges) {
      uint32_t keep = uint32_t(key >> 32), gone = uint32_t(key & 0xffffffffu);
      if (locked[keep] || locked[gone]) continue;
      const bool edgeOnBoundary = uses[key] == 1;
      if (boundary[keep] && boundary[gone] && !edgeOnBoundary) continue;  // would pinch the surface
      if (boundary[gone] && !boundary[keep]) std::swap(keep, gone);       // the boundary keeps its shape
      // Interior pairs meet halfway (half the change to every triangle around them, so far fewer
      // collapses are refused as flips); a boundary vertex keeps its place, and the hem its shape.
      const bool midpoint = !boundary[keep] && !boundary[gone];
      const Vec3f target = midpoint ? Vec3f(0.5f * (pos(keep) + pos(gone))) : pos(keep);
      const std::set<uint32_t> nk = neighbours(keep), ng = neighbours(gone);
      size_t common = 0;
      for (uint32_t u : nk) common += ng.count(u);
      if (common != size_t(uses[key])) continue;  // link condition: else the result is non-manifold
      bool flips = false;
      for (uint32_t end : {gone, keep})
        for (uint32_t t : around[end]) {
          const auto& tri = tris[t];
          if (std::find(tri.begin(), tri.end(), end == gone ? keep : gone) != tri.end())
            continue;  // removed with the edge
          Vec3f p[3], q[3];
          for (int k = 0; k < 3; ++k) p[k] = q[k] = pos(tri[size_t(k)]);
          for (int k = 0; k < 3; ++k)
            if (tri[size_t(k)] == end) q[k] = target;
          const Vec3f before = (p[1] - p[0]).cross(p[2] - p[0]), after = (q[1] - q[0]).cross(q[2] - q[0]);
          if (!(before.dot(after) > 0.25f * before.squaredNorm())) flips = true;
        }
      if (flips) continue;
      if (midpoint) {
        SkinWeights blended;
        blended.influences = n;
        blendWeights(skin, keep, gone, blended);
        std::copy(blended.joints.begin(), blended.joints.end(), skin.joints.begin() + std::ptrdiff_t(size_t(keep) * n));
        std::copy(blended.weights.begin(), blended.weights.end(),
                  skin.weights.begin() + std::ptrdiff_t(size_t(keep) * n));
        position[keep] = target;
      }
      for (uint32_t t : around[gone]) {
        auto& tri = tris[t];
        if (std::find(tri.begin(), tri.end(), keep) != tri.end())
          deadTri[t] = 1;
        else
          for (uint32_t& u : tri)
            if (u == gone) u = keep;
      }
      mergedInto[gone] = keep;
      locked[keep] = locked[gone] = 1;
      for (uint32_t u : nk) locked[u] = 1;
      for (uint32_t u : ng) locked[u] = 1;
      ++collapsed;
    }
    if (collapsed == 0) break;
  }

  // Compact: live vertices in their old order.
  auto root = [&](uint32_t v) {
    while (mergedInto[v] != v) v = mergedInto[v];
    return v;
  };
  std::vector<uint32_t> newIndex(nv, UINT32_MAX);
  uint32_t count = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (mergedInto[v] == v) newIndex[v] = count++;
  SimulationMesh out;
  out.refinedEdgeLength = in.refinedEdgeLength;
  out.skin.influences = in.skin.influences;
  out.restPositions.resize(count, 3);
  for (uint32_t v = 0; v < nv; ++v) {
    if (newIndex[v] == UINT32_MAX) continue;
    out.restPositions.row(newIndex[v]) = position[v].transpose();
    for (int k = 0; k < n; ++k) {
      out.skin.joints.push_back(skin.joints[size_t(v) * n + k]);
      out.skin.weights.push_back(skin.weights[size_t(v) * n + k]);
    }
  }
  size_t live = 0;
  for (uint8_t d : deadTri) live += !d;
  out.triangles.resize(Eigen::Index(live), 3);
  Eigen::Index row = 0;
  for (size_t t = 0; t < tris.size(); ++t) {
    if (deadTri[t]) continue;
    for (int k = 0; k < 3; ++k) out.triangles(row, k) = newIndex[root(tris[t][size_t(k)])];
    ++row;
  }
  out.gameToSim.resize(in.gameToSim.size());
  for (size_t g = 0; g < in.gameToSim.size(); ++g) out.gameToSim[g] = newIndex[root(in.gameToSim[g])];
  return out;
}

SimulationMesh buildSimulationMesh(const Character& character, size_t targetVertices) {
  const std::string what = "garment of character '" + character.name + "'";
  const size_t joints = character.skeleton.size();
  character.garment.validate(what, joints);
  if (character.garment.vertexCount() == 0 || character.garment.triangleCount() == 0)
    throw Error(what + ": the game mesh is empty");
  if (character.garment.skin.vertexCount() != character.garment.vertexCount())
    throw Error(what + ": the game mesh has no skin weights (the simulation needs them to follow the body)");

  std::vector<uint32_t> gameToWelded;
  if (character.simulationMesh) {
    const std::string simWhat = "simulation mesh of character '" + character.name + "'";
    const Mesh& m = *character.simulationMesh;
    m.validate(simWhat, joints);
    if (m.vertexCount() == 0 || m.triangleCount() == 0) throw Error(simWhat + ": empty");
    if (m.skin.vertexCount() != m.vertexCount()) throw Error(simWhat + ": has no skin weights");
    std::vector<uint32_t> simToWelded;
    SimulationMesh s = weldedSimulationMesh(m, simToWelded);
    requireManifoldEdges(s.triangles, simWhat);
    // Nearest simulation vertex per game vertex. Brute force: a few thousand by ~10^4, done once.
    s.gameToSim.resize(character.garment.vertexCount());
    for (size_t g = 0; g < s.gameToSim.size(); ++g) {
      const Eigen::RowVector3f p = character.garment.positions.row(Eigen::Index(g));
      Eigen::Index best = 0;
      (s.restPositions.rowwise() - p).rowwise().squaredNorm().minCoeff(&best);
      s.gameToSim[g] = uint32_t(best);
    }
    return s;
  }

  SimulationMesh s = weldedSimulationMesh(character.garment, gameToWelded);
  requireManifoldEdges(s.triangles, what);
  s.gameToSim = gameToWelded;
  if (targetVertices == 0) return s;
  if (s.vertexCount() >= targetVertices) {
    // Fine enough already; still, edges far shorter than the typical one (seams, hems) would be the
    // stiffest constraints of the solve and the first to fail: collapse them.
    std::vector<float> lengths;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
      for (int k = 0; k < 3; ++k)
        lengths.push_back(
            (s.restPositions.row(s.triangles(t, k)) - s.restPositions.row(s.triangles(t, (k + 1) % 3))).norm());
    std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2), lengths.end());
    return collapseShortEdges(s, 0.25f * lengths[lengths.size() / 2]);
  }
  // A mesh of even edges h has about area / (0.43 h^2) vertices (equilateral triangles, two per
  // vertex); bisection leaves edges between h/2 and h, so start there and correct the length by the
  // count it gave until the count is within 10% of the target (a few tries; each takes milliseconds).
  double area = 0.0;
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
    const Vec3f p0 = s.restPositions.row(s.triangles(t, 0)), p1 = s.restPositions.row(s.triangles(t, 1)),
                p2 = s.restPositions.row(s.triangles(t, 2));
    area += 0.5 * double((p1 - p0).cross(p2 - p0).norm());
  }
  if (!(area > 0.0)) throw Error(what + ": the game mesh has zero area");
  double edge = 1.4 * std::sqrt(area / (0.433 * double(targetVertices)));
  SimulationMesh best = s;
  for (int attempt = 0; attempt < 6; ++attempt) {
    // Bisection never makes an edge much shorter than half the length asked for; shorter ones come
    // from the game mesh (seams, hems) and only make the solve stiff where nothing is to be seen.
    SimulationMesh r = collapseShortEdges(refineToEdgeLength(s, float(edge)), 0.25f * float(edge));
    const double ratio = double(r.vertexCount()) / double(targetVertices);
    if (attempt == 0 ||
        std::abs(std::log(ratio)) < std::abs(std::log(double(best.vertexCount()) / double(targetVertices))))
      best = std::move(r);
    if (std::abs(ratio - 1.0) < 0.1) break;
    edge *= std::sqrt(ratio);
  }
  return best;
}

}  // namespace swish::bake
