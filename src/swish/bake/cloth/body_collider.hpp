#pragma once
// The skinned body as a collider for the cloth: closest point and signed distance to its triangle
// surface. Signs come from angle-weighted pseudo-normals (Baerentzen & Aanaes 2005), which are exact
// for closed manifold meshes whatever feature (face, edge, vertex) is closest. The surface is welded
// first (vertices at the same position are one): a glTF body is split at its UV seams, and only welded
// is it closed, its seam edges shared and its pseudo-normals those of both sides. Triangles are binned in
// a uniform grid rebuilt at every pose; queries visit only the cells that overlap their search ball.
//
// A body made of several closed parts that overlap (a mannequin's arm tubes pushed into its torso) is
// the union of the parts: the signed distance is the smallest of the parts' own signed distances, each
// part answered by its own closest triangle. Taking the single closest triangle of the whole soup
// instead would answer, in an armpit, with the arm tube's buried wall inside the torso, whose normal
// points the wrong way, and push the cloth into the body.
//
// Pseudo-normals are exact only for a surface that does not pass through itself. Skinning folds a
// tube at a sharply bent elbow through itself, and a point well outside the arm then finds its
// closest feature in the fold, facing away: "inside" by centimetres. So an inside answer deeper than
// kWindingCheckDepth from a closed part is confirmed by that part's winding number (robust to
// self-intersection) and turned to outside when the winding number says so.
//
// A body modelled as ONE closed surface (a glTF character: arms and torso one mesh) has one part where
// a mannequin has an arm tube and a torso: in its armpit the closest surface of the part is the arm or
// the torso, never both, and cloth trapped between them is pushed out of one into the other. So such a
// part is split into contact regions by skinning: each triangle goes with the joint group (`jointRegion`,
// e.g. the left arm chain, the right one, the rest) that holds most of its vertices' weights, and
// closestRegions answers per region. A part is split only where a joint group's triangles do not make
// a part of their own (more than half of that group's triangles lie in the part): a mannequin whose
// arms are separate tubes keeps one region per part, and the very answers of closestParts. A region
// is an open patch whose own pseudo-normals cannot tell inside from outside: the part's closest
// region (which holds the part's closest feature, confirmed by the part's winding number) decides. A
// point outside the part gets every region within reach, all outside; a point inside it gets the
// part's answer alone, as from an unsplit part.
#include <span>
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"

namespace swish::bake {

class BodyCollider {
 public:
  struct Hit {
    bool found = false;            // false: no surface within the search distance
    float signedDistance = 0.f;    // > 0 outside the body, < 0 inside
    Vec3f point = Vec3f::Zero();   // closest point on the surface
    Vec3f normal = Vec3f::Zero();  // unit, pointing out of the body at `point`
    int triangle = -1;             // the body triangle `point` lies on
    int part = -1;                 // the connected part that triangle belongs to
    int region = -1;               // its contact region (closestRegions): the part's id unless the part is split
  };

  // Inside answers deeper than this (metres) are confirmed by the winding number (see above).
  static constexpr float kWindingCheckDepth = 0.002f;

  // `body`: rest positions, triangles, skin weights (validated, naming `what`). `cellSize`: grid
  // spacing in metres, best about the usual search distance. `jointRegion`: a joint group per joint of
  // the skin (0: the trunk, others: limbs to split off a part that holds them, see above); empty or
  // all 0 splits nothing.
  BodyCollider(const Mesh& body, float cellSize, const std::string& what = "body",
               const std::vector<uint8_t>& jointRegion = {});

  // Poses the body by linear blend skinning and rebuilds normals and the grid.
  void pose(const std::vector<Mat4f>& skinMatrices);

  // Closest surface point to p within maxDistance (metres), of the whole body or, when onlyPart >= 0,
  // of that connected part alone, or, when skipPart >= 0, of the other parts. Thread-safe (const, no
  // scratch state).
  Hit closest(const Vec3f& p, float maxDistance, int onlyPart = -1, int skipPart = -1) const;

  // The closest surface point of each part within maxDistance, smallest signed distance first, at
  // most out.size() of them; returns how many were written. Where two parts meet in a crease (an arm
  // tube rising through the shoulder it is buried in) a point can be pushed out of one part into the
  // other: the cloth solver keeps a contact plane for each of the two deepest.
  size_t closestParts(const Vec3f& p, float maxDistance, std::span<Hit> out, int onlyPart = -1,
                      int skipPart = -1) const;

  // As closestParts, per contact region: a part split by skinning (see above) that p is outside of
  // answers once per region within reach, so a point in an armpit gets the arm and the torso of a
  // one-surface body. The first answer is always closestParts'; identical to closestParts where no
  // part is split.
  size_t closestRegions(const Vec3f& p, float maxDistance, std::span<Hit> out) const;

  // Contact region of each (welded) triangle; the part's id where the part is not split.
  const std::vector<uint32_t>& triangleRegions() const { return triangleRegion_; }
  // Whether some part is split into regions (else closestRegions is closestParts).
  bool splitsParts() const { return splitsParts_; }

  // Edges not shared by exactly two triangles (seam copies welded): 0 for a closed surface, the only
  // kind whose inside the signed distance tells reliably.
  size_t openEdges() const { return openEdges_; }

  // Generalised winding number of the posed part `part` (a Hit::part) at p: 1 inside a closed part
  // (2 where a fold overlaps itself), 0 outside, whatever folds skinning put in it. An open part or an
  // unknown id answers 1: its inside cannot be told this way. O(the part's triangles).
  float windingNumber(const Vec3f& p, int part) const;

  const Points3f& positions() const { return positions_; }
  const Triangles& triangles() const { return triangles_; }  // welded: indices of each position's first vertex

 private:
  void rebuild();
  void splitRegions(const std::vector<uint8_t>& jointRegion);
  size_t closestKeyed(const Vec3f& p, float maxDistance, std::span<Hit> out, int onlyPart, int skipPart,
                      bool byRegion) const;

  Points3f restPositions_;
  Triangles triangles_;
  SkinWeights skin_;
  std::vector<uint32_t> triangleEdges_;                // 3 per triangle: edge index of sides ab, bc, ca
  std::vector<std::array<int32_t, 2>> edgeTriangles_;  // up to two triangles per edge (-1: none)
  std::vector<uint32_t> triangleComponent_;            // connected part (by shared vertices) of each triangle
  std::vector<uint32_t> triangleRegion_;               // contact region of each triangle (see closestRegions)
  bool splitsParts_ = false;
  // Each part's triangles (partTriangles_[begin, end)), and whether the part is closed (every edge
  // shared by two of its triangles): only a closed part has a winding number to trust.
  struct PartRange {
    uint32_t part, begin, end;
    bool closed;
  };
  std::vector<PartRange> partRanges_;
  std::vector<uint32_t> partTriangles_;
  float cellSize_;
  size_t openEdges_ = 0;

  Points3f positions_;
  std::vector<Vec3f> faceNormals_, vertexNormals_, edgeNormals_;
  // The bounding sphere (centre xyz, radius) of each of a cell's triangles, in cellTriangles_' order: a
  // cheap reject before the exact test, read in a row instead of one cache line per triangle. Stored
  // as four arrays (kSphereLanes floats longer) so that a query rejects kSphereLanes at a time.
  static constexpr uint32_t kSphereLanes = 4;
  std::array<std::vector<float>, 4> cellSpheres_;
  Vec3f gridOrigin_ = Vec3f::Zero();
  Eigen::Vector3i gridDims_ = Eigen::Vector3i::Zero();
  std::vector<uint32_t> cellStart_, cellTriangles_;  // compressed rows: cell -> triangles
};

}  // namespace swish::bake
