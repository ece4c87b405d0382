#pragma once
// Penetration of a garment into the posed body: how many garment vertices lie inside the body (signed
// distance < 0 of the BodyCollider, the union of the body's parts) and how deep the deepest is. The
// measure of issue "no body through the cloth": used by `swish replay` per character and frame, and by
// the bake's evaluation on its held-out poses (truth and model side by side).
#include <cstdint>
#include <vector>

#include "swish/bake/cloth/body_collider.hpp"

namespace swish::bake {

// Depth (mm) beyond which a penetration counts as visible: below it, shading and the cloth's own
// thickness hide it.
inline constexpr double kVisiblePenetrationMm = 2.0;
// Vertices deeper than this (metres) are not searched for: no garment vertex sits that far inside a
// human body's surface, and the grid search stays local.
inline constexpr float kPenetrationSearch = 0.15f;
inline constexpr float kPenetrationNearSearch = 0.03f;  // tried first
// Grid cell (metres) of the body collider the measures above search (the bake's evaluation, the replay's
// penetration and its truth split).
inline constexpr float kPenetrationCellSize = 0.05f;

struct PenetrationStats {
  uint32_t vertices = 0;  // garment vertices measured
  uint32_t inside = 0;    // with signed distance < 0
  uint32_t visible = 0;   // deeper than kVisiblePenetrationMm
  double deepestMm = 0;   // 0 when none is inside
  double share() const { return vertices ? double(inside) / vertices : 0.0; }
};

// `collider` posed as the garment is (BodyCollider::pose with the same skinning matrices); `garment`
// in the same space. Thread-safe (const).
PenetrationStats measurePenetration(const BodyCollider& collider, const Points3f& garment);

// How deep (metres, > 0) a point lies inside the posed body; 0 outside it, beyond kPenetrationSearch or
// not finite. What measurePenetration counts, per point. Thread-safe (const).
float penetrationDepth(const BodyCollider& collider, const Vec3f& p);

// Pools frames or poses: sums of counts, the deepest of all; `frames` counts the pooled measurements
// and `framesVisible` those with at least one visible penetration.
struct PenetrationPool {
  uint64_t vertices = 0, inside = 0, visible = 0;
  uint32_t frames = 0, framesVisible = 0, framesInside = 0;
  double deepestMm = 0;
  std::vector<double> frameDeepestMm;  // per pooled measurement, in order (for percentiles)
  void add(const PenetrationStats& s);
  double share() const { return vertices ? double(inside) / double(vertices) : 0.0; }
  double deepestPercentileMm(double q) const;  // over the pooled measurements' deepest
};

}  // namespace swish::bake
