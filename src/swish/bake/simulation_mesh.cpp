#include "swish/bake/simulation_mesh.hpp"

#include <algorithm>
#include <cmath>
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
      if (it == merged.end()) merged.push_back({j, w});
      else it->second += w;
    }
  std::sort(merged.begin(), merged.end(), [](auto& x, auto& y) {
    return x.second != y.second ? x.second > y.second : x.first < y.first;
  });
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

SimulationMesh subdivideMidpoint(const SimulationMesh& in) {
  SimulationMesh out;
  out.gameToSim = in.gameToSim;
  out.subdivisionLevels = in.subdivisionLevels + 1;
  out.fromCharacterSimulationMesh = in.fromCharacterSimulationMesh;
  out.skin.influences = in.skin.influences;
  out.skin.joints = in.skin.joints;
  out.skin.weights = in.skin.weights;

  // Midpoints numbered in first-visit order over the triangles: deterministic.
  std::unordered_map<uint64_t, uint32_t> midpoint;
  midpoint.reserve(size_t(in.triangles.rows()) * 2);
  std::vector<std::pair<uint32_t, uint32_t>> newEdges;
  const uint32_t base = uint32_t(in.vertexCount());
  auto mid = [&](uint32_t a, uint32_t b) {
    auto [it, inserted] = midpoint.try_emplace(edgeKey(a, b), base + uint32_t(newEdges.size()));
    if (inserted) newEdges.push_back({a, b});
    return it->second;
  };
  out.triangles.resize(in.triangles.rows() * 4, 3);
  for (Eigen::Index t = 0; t < in.triangles.rows(); ++t) {
    const uint32_t a = in.triangles(t, 0), b = in.triangles(t, 1), c = in.triangles(t, 2);
    const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    out.triangles.row(4 * t + 0) << a, ab, ca;
    out.triangles.row(4 * t + 1) << ab, b, bc;
    out.triangles.row(4 * t + 2) << ca, bc, c;
    out.triangles.row(4 * t + 3) << ab, bc, ca;
  }
  out.restPositions.resize(base + newEdges.size(), 3);
  out.restPositions.topRows(base) = in.restPositions;
  for (size_t e = 0; e < newEdges.size(); ++e) {
    out.restPositions.row(base + e) =
        0.5f * (in.restPositions.row(newEdges[e].first) + in.restPositions.row(newEdges[e].second));
    blendWeights(in.skin, newEdges[e].first, newEdges[e].second, out.skin);
  }
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
    s.fromCharacterSimulationMesh = true;
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
  // One level adds one vertex per edge: keep subdividing while that lands closer to the target
  // (compared by ratio, so "about 12,000" means the same above and below).
  while (targetVertices > 0) {
    const double now = double(s.vertexCount());
    const double edges = double(s.triangles.rows()) * 1.5;  // exact for closed meshes, close for open ones
    const double next = now + edges;
    if (std::abs(std::log(next / double(targetVertices))) >= std::abs(std::log(now / double(targetVertices)))) break;
    s = subdivideMidpoint(s);
  }
  return s;
}

}  // namespace swish::bake
