#pragma once
// The game mesh covers the body where the simulation covered it (part1.transfer.cover_body_mm).
//
// The game mesh follows the simulation mesh vertex by vertex (mesh_transfer.hpp), but it is coarser: its
// triangles are chords of the cloth the simulation wrapped around the body. Where the body is sharply
// convex (the tops of the shoulders, where the arm meets the trunk) a game triangle cuts under the skin
// although every one of its corners lies on cloth that the simulation kept outside the body, and the
// player sees the body through the jersey (measured on the default bake: issue 19, docs/baking.md). The
// model learns whatever the dataset stores, so the fix belongs here, in the stored shape.
//
// Per pose (the game mesh as transferred and smoothed, the body posed as simulated), in rounds: every
// sample of the body's surface (vertices and triangle centroids) within `reach` of the game mesh whose
// nearest game triangle has it in front of its outward side (the skin through the garment), and which
// the simulation's cloth covers there (the simulated surface nearest to it is outside it: the game mesh
// lost what the simulation had), asks the triangle's corners to move out by the depth plus `margin`, shared
// by barycentric weight so that the triangle passes `margin` above the sample (delta_i = b_i * d / sum b_j^2;
// samples less than 0.5 mm through ask nothing). Each vertex takes the largest ask, and its neighbours at least
// half of it (three rings: a smooth bump); it moves along its vertex normal where that is within 30 degrees of
// the asking triangle's normal, the way the triangle faces beyond 60 (a fold, where neighbouring vertex normals
// point apart), blended between. A sample a round did not take halfway out is given up; the total shift of a
// vertex is bounded by `maxShift`. Last, no edge tears: the ends of any edge the cover stretched past 200 %
// strain (and its length before) give back part of their moves (BodyCoverStats::verticesHeld; measured on
// the corpus, docs/baking.md). Triangles on the
// garment's openings (hem, collar, sleeve ends) ask nothing: a body beyond a hem is not under the cloth. Where the
// simulation itself has the body through its cloth nothing is asked either: that is the simulation's fault (issue 18),
// not the transfer's.
//
// Where limb clearance simulated another pose than the recorded one, the same runs again once the game mesh is
// skinned back to the recorded pose (pose_shape.hpp step 4): the samples the cloth covered in the simulated
// pose, posed as recorded, against the re-skinned game mesh (coveredSamples, then apply with that mask).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "swish/core/mesh_frames.hpp"
#include "swish/core/types.hpp"

namespace swish::bake {

struct BodyCoverSettings {
  float margin = 0.002f;   // m above the skin the game mesh passes; 0: off
  float maxShift = 0.03f;  // m: no vertex moves further (the chord error of a coarse game mesh is below this)
  float reach = 0.03f;     // m: body samples farther from the game mesh are not under it
  int rounds = 4;          // moving a vertex can uncover a neighbouring triangle's sample
  // Also in the recorded pose, where limb clearance changed the simulated one (pose_shape.hpp step 4). Datasets
  // and models from before it was a setting (session 28) did not (their settings lack the key).
  bool recordedPose = true;
  bool enabled() const { return margin > 0.f; }
};

struct BodyCoverStats {
  size_t samplesThrough = 0;  // body samples through the game mesh before (the simulation covering them)
  size_t samplesLeft = 0;     // the same after the last round
  float deepest = 0.f;        // m, before
  size_t verticesMoved = 0;
  float largestShift = 0.f;  // m
  size_t verticesHeld = 0;   // held back (part of their move taken back) so that no edge tears
};

// Built once per garment: its seam copies welded by rest position (they move together) and the vertices
// on its openings (edges of one triangle once welded).
class BodyCover {
 public:
  // `gameRest`/`gameTriangles`: the game mesh at rest, triangles winding outwards; `bodyRest`/`bodyTriangles`:
  // the body's. Throws Error for indices out of range or a bad setting.
  BodyCover(const Points3f& gameRest, const Triangles& gameTriangles, const Points3f& bodyRest,
            const Triangles& bodyTriangles, const BodyCoverSettings& settings);

  // Moves `game` (the posed game mesh) in place; `body`: the body posed as simulated; `simulation` with
  // `simulationTriangles`: the simulated cloth the game mesh was transferred from. Deterministic. Throws
  // Error for vertex counts that do not match or non-finite positions.
  BodyCoverStats apply(Points3f& game, const Points3f& body, const Points3f& simulation,
                       const Triangles& simulationTriangles) const;

  // The two halves of apply(). coveredSamples: which of the body's samples (its vertices, then its
  // triangles' centroids) the simulated cloth covers, with `body` posed as simulated. apply with that mask:
  // moves `game` off `body` where a covered sample is through it. The body and the game mesh may be in
  // another pose than the simulation's, as long as the samples keep their meaning: after limb clearance
  // (pose_shape.hpp step 4) a sample the cloth covered round the turned-out arm is still the skin the
  // sleeve must cover once the arm is back where it was recorded.
  std::vector<char> coveredSamples(const Points3f& body, const Points3f& simulation,
                                   const Triangles& simulationTriangles) const;
  BodyCoverStats apply(Points3f& game, const Points3f& body, const std::vector<char>& covered) const;

 private:
  void checkBody(const Points3f& body) const;  // throws for a body of another vertex count
  // Takes back part of the moves (`game` against `before`) of the ends of any edge the cover stretched past
  // its bound (body_cover.cpp, kCoverStrain).
  void holdTears(Points3f& game, const Points3f& before, BodyCoverStats& stats) const;

  BodyCoverSettings settings_;
  std::vector<uint32_t> weld_;  // game vertex -> its welded representative (the first at its rest position)
  Triangles welded_;            // game triangles on the representatives
  std::vector<char> opening_;   // per game vertex
  std::vector<std::vector<uint32_t>> neighbours_;     // of each representative, over the welded triangles
  std::vector<std::pair<uint32_t, uint32_t>> edges_;  // the welded triangles' unique edges
  std::vector<float> edgeRest_;                       // their rest lengths
  MeshFrameTopology gameTopology_, bodyTopology_;     // for their area-weighted vertex normals, seams welded
  Triangles bodyTriangles_;
};

}  // namespace swish::bake
