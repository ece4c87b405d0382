#include "swish/bake/report/penetration.hpp"

#include <algorithm>
#include <cmath>

namespace swish::bake {

float penetrationDepth(const BodyCollider& collider, const Vec3f& p) {
  if (!p.allFinite()) return 0.f;
  // Most garment vertices lie within a couple of centimetres of the body: a small search ball
  // answers them from a few grid cells; only the rest pay for the full depth.
  BodyCollider::Hit h = collider.closest(p, kPenetrationNearSearch);
  if (!h.found) h = collider.closest(p, kPenetrationSearch);
  return h.found && h.signedDistance < 0.f ? -h.signedDistance : 0.f;
}

PenetrationStats measurePenetration(const BodyCollider& collider, const Points3f& garment) {
  PenetrationStats s;
  s.vertices = uint32_t(garment.rows());
  for (Eigen::Index v = 0; v < garment.rows(); ++v) {
    const float depth = penetrationDepth(collider, garment.row(v).transpose());
    if (!(depth > 0.f)) continue;
    const double mm = 1000.0 * double(depth);
    ++s.inside;
    if (mm > kVisiblePenetrationMm) ++s.visible;
    s.deepestMm = std::max(s.deepestMm, mm);
  }
  return s;
}

void PenetrationPool::add(const PenetrationStats& s) {
  vertices += s.vertices, inside += s.inside, visible += s.visible;
  ++frames;
  if (s.visible) ++framesVisible;
  if (s.inside) ++framesInside;
  deepestMm = std::max(deepestMm, s.deepestMm);
  frameDeepestMm.push_back(s.deepestMm);
}

double PenetrationPool::deepestPercentileMm(double q) const {
  if (frameDeepestMm.empty()) return 0.0;
  std::vector<double> d = frameDeepestMm;
  std::sort(d.begin(), d.end());
  const size_t i = size_t(std::ceil(q * double(d.size())));
  return d[std::min(d.size() - 1, i == 0 ? 0 : i - 1)];
}

}  // namespace swish::bake
