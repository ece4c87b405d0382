#pragma once
// Which body triangles the garment covers in (nearly) every training pose (issue: "hide what games hide"). A
// game does not draw the skin under a tight garment; the preview renderer and a host can do the same
// with this list (Model::bodyCoverage, api::ModelInfo::coveredBodyTriangles), so that a body the
// garment sits on can never show through it.
//
// A body triangle is covered in a pose when the line along its outward normal through its centroid meets
// the garment (either side) between maxInside below the surface and maxGap above it: a garment the
// simulation left a little inside the body still covers it (that is where a body shows through). It
// is listed when it is covered in at least minShare of the poses given (1: every one). The defaults
// were set on the small corpus bake (docs/baking.md), whose simulations leave the jersey loose and
// sometimes inside the body or torn (issue 18): with a 4 cm gap, 2 cm inside and every pose, 24 of the
// 2947 triangles its first pose covers were left; with 8 cm, 5 cm and 98 % of the poses, 886. The body
// is skinned per pose with the character's own skeleton, the garment is the pose's simulated game
// mesh (DatasetPose::gameMeshWorld, the shape the network learns).
//
// A triangle buried in another part of the posed body (the end of an arm tube inside the trunk when
// the arm is raised: the mannequin's limbs are separate tubes that overlap the trunk) cannot show in
// that pose either, so it counts as hidden there (`buriedCounts`): a triangle is listed when in
// minShare of the poses it is covered or buried, and covered in at least one. Without that, the arm
// tube's upper end, which the jersey's shoulder covers when the arm hangs and the trunk hides when it
// is raised, was never listed, and it is what showed through the shoulders of the default scene.
#include <cstdint>
#include <optional>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

struct BodyCoverageOptions {
  float maxGap = 0.08f;      // m between the body and the garment above it
  float maxInside = 0.05f;   // m of garment sunk into the body that still covers it
  double minShare = 0.98;    // of the poses tested
  size_t maxPoses = 400;     // evenly spaced over the poses given, for the cost (a few ms per pose)
  bool buriedCounts = true;  // a triangle inside another part of the body counts as hidden (see above)
};
// A triangle's centroid is buried when it lies deeper than this (metres) inside another part, searched
// this far.
inline constexpr float kBuriedDepth = 0.001f, kBuriedSearch = 0.1f;

struct BodyCoverageResult {
  uint32_t bodyTriangles = 0;           // the body's triangle count (the list's indices refer to it)
  std::vector<uint32_t> covered;        // ascending
  size_t poses = 0;                     // poses tested
  size_t coveredAtRest = 0;             // triangles covered in the first pose tested, for the report
  std::vector<uint32_t> perPose;        // triangles covered in each pose tested, by itself
  std::vector<uint32_t> buriedPerPose;  // triangles not covered but buried in another part, each pose tested
  // Triangles covered in at least 50, 80, 90, 95, 98 and 100 % of the poses tested.
  std::vector<std::pair<double, uint32_t>> byShare;
};

BodyCoverageResult coveredBodyTriangles(const Character& character, const std::vector<const DatasetPose*>& poses,
                                        const BodyCoverageOptions& options = {});

// The test above for one body triangle (corners a, b, c, winding outwards): the garment's first hit on
// the line along the triangle's outward normal through its centroid, from `from` metres along the normal
// (negative: below the skin) over `length` metres. nullopt for a degenerate triangle (no normal). The
// replay's body-through-the-garment measure (replay/body_through_garment.hpp) decides coverage at rest
// with it too.
std::optional<SurfacePoint> garmentAlongNormal(const Vec3f& a, const Vec3f& b, const Vec3f& c,
                                               const TriangleRayScene& garment, float from, float length);

}  // namespace swish::bake
