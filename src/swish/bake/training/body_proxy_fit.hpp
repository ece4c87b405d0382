#pragma once
// Fits the body proxy of the run-time push-out (BodyProxy in model/model.hpp) to a character's body:
// one capsule per (joint, connected body part) group of the body's vertices whose largest skin weight
// is that joint, riding on that joint.
//
// Per group: the capsule's axis is one of the group's three principal axes (rest pose), each end of its
// segment somewhere from the group's middle to half its extent beyond the group (consecutive groups'
// capsules then overlap), its radius the largest that keeps every vertex, edge
// midpoint and triangle centre of the group's part outside it; of the axis/length candidates the one of
// largest volume wins (a long thin capsule in an arm, a short wide one across a flat chest). Then the
// capsule is checked against the real body: points on its surface must not lie outside the body by
// more than kInsideTolerance (signed distance of the rest-pose BodyCollider, the union of the parts);
// where one does, the radius shrinks by that much and the check repeats. So the proxy lies inside the
// body, and pushing a garment vertex out to it never carries the vertex past the real surface.
//
// A capsule is kept when it is at least minRadius thick and comes within `reach` of the garment's rest
// bounding box (a foot never reaches a shirt; a forearm crossing the chest does), at most
// kMaxBodyCapsules of them, nearest to the garment first.
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct BodyProxyFitSettings {
  float reach = 0.5f;       // metres from the garment's rest bounds; < 0 keeps every capsule
  float minRadius = 0.01f;  // metres
  size_t minVertices = 8;   // smaller groups get no capsule
};

// How far (metres) a capsule's surface may stand outside the body after the check: the sampling's
// resolution, below what the penetration measure reports.
inline constexpr float kInsideTolerance = 0.0005f;

struct BodyProxyFit {
  BodyProxy proxy;
  std::vector<std::string> capsuleJoints;  // joint name of each capsule (for reports)
  size_t groups = 0;                       // (joint, part) groups considered
  size_t dropped = 0;                      // too thin, too far from the garment, or beyond the cap
  float worstOutsideMm = 0;  // largest distance outside the body of a checked surface point, after shrinking
};

// `body` skinned to `skeleton` (rest positions, triangles, skin); `garment`: the game mesh at rest
// (its bounds decide `reach`; nullptr keeps every capsule). Throws Error naming the problem for an
// invalid body. Deterministic.
BodyProxyFit fitBodyProxy(const Mesh& body, const Skeleton& skeleton, const Mesh* garment,
                          const BodyProxyFitSettings& settings = {});

}  // namespace swish::bake
