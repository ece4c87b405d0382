#include "swish/bake/transfer/body_cover.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"

namespace swish::bake {

namespace {

// Barycentric share below which a closest point counts as on the triangle's edge.
constexpr float kInside = 0.02f;
// A body sample less than this (m) through the game mesh is left alone: rounding where the cloth lies on
// the skin, and nothing a player sees.
constexpr float kThrough = 0.0005f;
// A moved vertex's neighbours move at least this share of its move, over this many rings.
constexpr float kFalloff = 0.5f;
constexpr int kFalloffRings = 3;
// The cover stretches no edge past this strain (half the transfer's tear bound, part1.transfer.max_edge_strain
// 400 %) unless it was longer before; the ends of one it would take back part of their moves, in up to
// kHoldRounds rounds of kHoldBack each (then all of them). Measured on corpus poses (docs/baking.md): a bound
// of half the rest length beyond the length before held back the first cover's smooth bumps too, and left the
// body through in 84 of 200 poses (15 without a bound, 36 with this one).
constexpr float kCoverStrain = 2.f, kHoldBack = 0.7f;
constexpr int kHoldRounds = 12;
// The cosine between the skin's normal and the game triangle's at which a sample counts half; its share goes
// from 0 to 1 over kFacingBlend around it.
constexpr float kFacing = 0.7f, kFacingBlend = 0.2f;
// A vertex moves along its normal where that is within 30 degrees of the asking triangle's (cosine kAlong),
// the way the triangle faces beyond 60 (kAcross), blended between.
constexpr float kAlong = 0.866f, kAcross = 0.5f;

Vec3f faceNormal(const Points3f& p, const Triangles& t, Eigen::Index k) {
  const Vec3f a = p.row(t(k, 0)), b = p.row(t(k, 1)), c = p.row(t(k, 2));
  const Vec3f n = (b - a).cross(c - a);
  const float len = n.norm();
  return len > 0.f ? Vec3f(n / len) : Vec3f::Zero();
}

}  // namespace

BodyCover::BodyCover(const Points3f& gameRest, const Triangles& gameTriangles, const Points3f& bodyRest,
                     const Triangles& bodyTriangles, const BodyCoverSettings& settings)
    : settings_(settings), bodyTriangles_(bodyTriangles) {
  if (!(settings.margin >= 0.f && settings.margin <= 0.02f))
    throw Error("body cover: the margin must be in [0, 20] mm");
  if (!(settings.maxShift > 0.f && settings.maxShift <= 0.1f) || !(settings.reach > 0.f && settings.reach <= 0.2f) ||
      settings.rounds < 1)
    throw Error("body cover: the largest shift, the reach and the rounds must be positive");
  if (gameTriangles.size() > 0 && Eigen::Index(gameTriangles.maxCoeff()) >= gameRest.rows())
    throw Error("body cover: a game-mesh triangle names a vertex out of range");
  weld_ = weldByPosition(gameRest);
  welded_ = trianglesWeldedByPosition(gameRest, gameTriangles);
  opening_.assign(size_t(gameRest.rows()), 0);
  for (const auto& [a, b] : openEdges(welded_)) opening_[a] = opening_[b] = 1;
  for (Eigen::Index v = 0; v < gameRest.rows(); ++v) opening_[size_t(v)] = opening_[weld_[size_t(v)]];
  if (bodyTriangles.size() > 0 && Eigen::Index(bodyTriangles.maxCoeff()) >= bodyRest.rows())
    throw Error("body cover: a body triangle names a vertex out of range");
  neighbours_ = buildVertexNeighbours(welded_, size_t(gameRest.rows()));
  edges_ = uniqueEdges(neighbours_);
  edgeRest_ = edgeLengths(gameRest, edges_);
  gameTopology_ = buildFrameTopology(gameTriangles, gameRest);
  bodyTopology_ = buildFrameTopology(bodyTriangles, bodyRest);
}

namespace {

// The body's surface samples, with their outward normals: its vertices (area-weighted normals) and its
// triangles' centroids.
void bodySamples(const Points3f& body, const Triangles& triangles, const MeshFrameTopology& topology, Points3f& samples,
                 Points3f& normals) {
  samples.resize(body.rows() + triangles.rows(), 3);
  normals.resize(samples.rows(), 3);
  samples.topRows(body.rows()) = body;
  normals.topRows(body.rows()) = surfaceVertexNormals(body, triangles, topology);
  for (Eigen::Index k = 0; k < triangles.rows(); ++k) {
    samples.row(body.rows() + k) =
        (body.row(triangles(k, 0)) + body.row(triangles(k, 1)) + body.row(triangles(k, 2))) / 3.f;
    normals.row(body.rows() + k) = faceNormal(body, triangles, k).transpose();
  }
}

}  // namespace

void BodyCover::checkBody(const Points3f& body) const {
  if (size_t(body.rows()) != bodyTopology_.normalAdjacency.offsets.size() - 1)
    throw Error("body cover: the posed body has " + std::to_string(body.rows()) + " vertices, at rest " +
                std::to_string(bodyTopology_.normalAdjacency.offsets.size() - 1));
}

std::vector<char> BodyCover::coveredSamples(const Points3f& body, const Points3f& simulation,
                                            const Triangles& simulationTriangles) const {
  checkBody(body);
  Points3f samples, sampleNormals;
  bodySamples(body, bodyTriangles_, bodyTopology_, samples, sampleNormals);
  const TriangleRayScene cloth(simulation, simulationTriangles, "body cover: simulated cloth");
  // Which samples the simulation covers: the nearest simulated surface is outside them (or less than
  // kThrough inside).
  std::vector<char> covered(size_t(samples.rows()), 0);
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    const Vec3f b = samples.row(i);
    const SurfacePoint s = cloth.closestPoint(b, settings_.reach);
    if (s.found)
      covered[size_t(i)] = (b - s.point).dot(faceNormal(simulation, simulationTriangles, s.triangle)) <= kThrough;
  }
  return covered;
}

BodyCoverStats BodyCover::apply(Points3f& game, const Points3f& body, const Points3f& simulation,
                                const Triangles& simulationTriangles) const {
  if (!settings_.enabled()) return {};
  return apply(game, body, coveredSamples(body, simulation, simulationTriangles));
}

BodyCoverStats BodyCover::apply(Points3f& game, const Points3f& body, const std::vector<char>& covered) const {
  BodyCoverStats stats;
  if (!settings_.enabled()) return stats;
  if (size_t(game.rows()) != weld_.size())
    throw Error("body cover: the game mesh has " + std::to_string(game.rows()) + " vertices, at rest " +
                std::to_string(weld_.size()));
  checkBody(body);
  Points3f samples, sampleNormals;
  bodySamples(body, bodyTriangles_, bodyTopology_, samples, sampleNormals);
  if (covered.size() != size_t(samples.rows()))
    throw Error("body cover: the covered samples do not belong to this body");
  // One pass over the covered samples against the game mesh as it is: how many are through it, and (when
  // `ask` is given) how far each representative is asked to move out, and the deepest. A sample that the
  // last round's moves did not take at least halfway out is given up (moving along the vertex normals does
  // not reach it: a crease), so that no vertex is pushed round after round into a tear.
  std::vector<float> lastDepth(size_t(samples.rows()), std::numeric_limits<float>::infinity());
  std::vector<char> asking = covered;
  auto pass = [&](std::vector<Vec3f>* ask, float* deepest) {
    const TriangleRayScene mesh(game, welded_, "body cover: game mesh");
    size_t through = 0;
    for (Eigen::Index i = 0; i < samples.rows(); ++i) {
      if (!covered[size_t(i)]) continue;
      const Vec3f b = samples.row(i);
      const SurfacePoint g = mesh.closestPoint(b, settings_.reach);
      if (!g.found) continue;
      const Eigen::Index t = g.triangle;
      if (opening_[size_t(welded_(t, 0))] || opening_[size_t(welded_(t, 1))] || opening_[size_t(welded_(t, 2))])
        continue;
      // Over the triangle's inside only: at an edge or a corner the nearest triangle's side says little (a
      // crease such as the armpit), and a chord's cut lies inside it.
      if (!(g.u > kInside && g.v > kInside && 1.f - g.u - g.v > kInside)) continue;
      const Vec3f n = faceNormal(game, welded_, t);
      const float depth = (b - g.point).dot(n);
      if (!(depth > kThrough)) continue;
      // The skin faces the way the cloth over it does (a shoulder under the yoke), not across it (the trunk's
      // side under a sleeve in the armpit's crease, where moving the sleeve out tears it).
      const float facing = std::clamp((n.dot(sampleNormals.row(i)) - kFacing) / kFacingBlend + 0.5f, 0.f, 1.f);
      if (!(facing > 0.f)) continue;
      ++through;
      if (deepest) *deepest = std::max(*deepest, depth);
      if (!ask || !asking[size_t(i)]) continue;
      if (!(depth < 0.5f * lastDepth[size_t(i)])) {
        asking[size_t(i)] = 0;
        continue;
      }
      lastDepth[size_t(i)] = depth;
      // The ask grows from 0 at kThrough: continuous in the pose, so that a sample crossing the threshold
      // does not add a bump to the stored shape at once (the model learns a smooth function of the pose).
      const float over = depth - kThrough;
      const float d = facing * (over + settings_.margin * std::min(1.f, over / kThrough));
      const float w[3] = {1.f - g.u - g.v, g.u, g.v};
      const float norm = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
      for (int e = 0; e < 3; ++e) {  // a vertex keeps its largest ask, along the asking triangle's normal
        Vec3f& a = (*ask)[size_t(welded_(t, e))];
        const float length = w[e] * d / norm;
        if (length > a.norm()) a = length * n;
      }
    }
    return through;
  };
  const Points3f before = game;
  std::vector<float> shifted(size_t(game.rows()), 0.f);
  std::vector<Vec3f> ask(size_t(game.rows()));
  for (int round = 0; round < settings_.rounds; ++round) {
    std::fill(ask.begin(), ask.end(), Vec3f::Zero());
    const size_t through = pass(&ask, round == 0 ? &stats.deepest : nullptr);
    if (round == 0) stats.samplesThrough = through;
    if (through == 0) break;
    // A smooth bump, not a spike: each vertex moves at least half as far as its farthest-moving neighbour
    // (three rings), and the same way, so that no edge between a moved vertex and a still one tears.
    for (int ring = 0; ring < kFalloffRings; ++ring) {
      const std::vector<Vec3f> last = ask;
      for (size_t v = 0; v < neighbours_.size(); ++v) {
        float longest = ask[v].norm();
        for (uint32_t u : neighbours_[v]) {
          const float length = kFalloff * last[u].norm();
          if (length > longest) {
            ask[v] = kFalloff * last[u];
            longest = length;
          }
        }
      }
    }
    // Out along the area-weighted vertex normals (seam copies share theirs) where they agree with the way the
    // asking triangle faces, else that way: in a fold of the game mesh (a sleeve skinned back against the
    // trunk) neighbouring vertex normals point apart, and moving along them tore the edges between (blended
    // between kAlong and kAcross, continuous in the pose).
    const Points3f normals = surfaceVertexNormals(game, welded_, gameTopology_);
    for (Eigen::Index v = 0; v < game.rows(); ++v) {
      const float length = ask[size_t(v)].norm();
      const float step = std::min(length, settings_.maxShift - shifted[size_t(v)]);
      if (!(step > 0.f) || weld_[size_t(v)] != uint32_t(v)) continue;
      const Vec3f facing = ask[size_t(v)] / length, normal = normals.row(v);
      const float x = std::clamp((normal.dot(facing) - kAcross) / (kAlong - kAcross), 0.f, 1.f);
      const float w = x * x * (3.f - 2.f * x);
      const Vec3f way = w * normal + (1.f - w) * facing;
      const float wayLength = way.norm();
      game.row(v) += (wayLength > 0.f ? Vec3f(way / wayLength) : facing).transpose() * step;
      shifted[size_t(v)] += step;
    }
    for (Eigen::Index v = 0; v < game.rows(); ++v) game.row(v) = game.row(weld_[size_t(v)]);  // seam copies follow
  }
  if (stats.samplesThrough > 0) holdTears(game, before, stats);
  stats.samplesLeft = stats.samplesThrough > 0 ? pass(nullptr, nullptr) : 0;
  for (Eigen::Index v = 0; v < game.rows(); ++v) {
    const float shift = (game.row(v) - before.row(v)).norm();
    if (!(shift > 0.f)) continue;
    ++stats.verticesMoved;
    stats.largestShift = std::max(stats.largestShift, shift);
  }
  return stats;
}

void BodyCover::holdTears(Points3f& game, const Points3f& before, BodyCoverStats& stats) const {
  // The bound per edge, from the shape before the cover.
  std::vector<float> bound = edgeLengths(before, edges_);
  for (size_t e = 0; e < edges_.size(); ++e) bound[e] = std::max(bound[e], (1.f + kCoverStrain) * edgeRest_[e]);
  // Each representative's share of its move; an over-stretched edge's ends give some back.
  std::vector<float> share(size_t(game.rows()), 1.f);
  const Points3f moved = game;
  auto place = [&] {
    for (Eigen::Index v = 0; v < game.rows(); ++v) {
      const Eigen::Index r = weld_[size_t(v)];
      game.row(v) = before.row(r) + share[size_t(r)] * (moved.row(r) - before.row(r));
    }
  };
  std::vector<char> held(share.size(), 0);
  for (int round = 0; round <= kHoldRounds; ++round) {
    bool over = false;
    for (size_t e = 0; e < edges_.size(); ++e) {
      const auto [a, b] = edges_[e];
      if (!((game.row(a) - game.row(b)).norm() > bound[e])) continue;
      over = true;
      held[a] = held[b] = 1;
      const float keep = round < kHoldRounds ? kHoldBack : 0.f;
      share[a] *= keep;
      share[b] *= keep;
    }
    if (!over) break;
    place();
  }
  stats.verticesHeld = size_t(std::count(held.begin(), held.end(), char(1)));
}

}  // namespace swish::bake
