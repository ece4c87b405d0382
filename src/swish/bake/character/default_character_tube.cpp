#include "swish/bake/character/default_character_tube.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

// Uniform Catmull-Rom through p1..p2 with neighbours p0, p3; and its derivative.
template <class T>
T catmullRom(const T& p0, const T& p1, const T& p2, const T& p3, float t) {
  const float t2 = t * t, t3 = t2 * t;
  return 0.5f * ((2.f * p1) + (-p0 + p2) * t + (2.f * p0 - 5.f * p1 + 4.f * p2 - p3) * t2 +
                 (-p0 + 3.f * p1 - 3.f * p2 + p3) * t3);
}
Vec3f catmullRomDerivative(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2, const Vec3f& p3, float t) {
  const float t2 = t * t;
  return 0.5f *
         ((-p0 + p2) + 2.f * (2.f * p0 - 5.f * p1 + 4.f * p2 - p3) * t + 3.f * (-p0 + 3.f * p1 - 3.f * p2 + p3) * t2);
}

}  // namespace

SweptEllipseTube::SweptEllipseTube(std::vector<TubeStation> stations, int denseSamplesPerSpan)
    : stations_(std::move(stations)) {
  if (stations_.size() < 2) throw Error("swept-ellipse tube needs at least two stations");
  const int n = int(stations_.size() - 1) * denseSamplesPerSpan;
  dense_.reserve(size_t(n) + 1);
  for (int i = 0; i <= n; ++i) dense_.push_back(section(float(i) / float(denseSamplesPerSpan)));
}

TubeSection SweptEllipseTube::section(float param) const {
  const int last = int(stations_.size()) - 1;
  param = std::clamp(param, 0.f, float(last));
  const int i = std::min(int(param), last - 1);
  const float t = param - float(i);
  auto at = [&](int k) { return stations_[size_t(std::clamp(k, 0, last))]; };
  // Phantom end stations continue the first/last span straight, so the ends do not curl.
  auto centerAt = [&](int k) -> Vec3f {
    if (k < 0) return 2.f * at(0).center - at(1).center;
    if (k > last) return 2.f * at(last).center - at(last - 1).center;
    return at(k).center;
  };
  TubeSection s;
  s.param = param;
  s.center = catmullRom(centerAt(i - 1), centerAt(i), centerAt(i + 1), centerAt(i + 2), t);
  Vec3f d = catmullRomDerivative(centerAt(i - 1), centerAt(i), centerAt(i + 1), centerAt(i + 2), t);
  if (d.norm() < 1e-9f) d = centerAt(i + 1) - centerAt(i);
  s.tangent = d.normalized();
  // Radii: monotone-ish blend (smoothstep between stations) so they never overshoot below zero.
  const float w = t * t * (3.f - 2.f * t);
  s.halfWidth = (1.f - w) * at(i).halfWidth + w * at(i + 1).halfWidth;
  s.halfDepth = (1.f - w) * at(i).halfDepth + w * at(i + 1).halfDepth;
  Vec3f e1 = s.tangent.cross(Vec3f::UnitZ());
  if (e1.norm() < 0.2f) e1 = Vec3f::UnitY().cross(s.tangent);
  s.e1 = e1.normalized();
  s.e2 = s.tangent.cross(s.e1).normalized();
  return s;
}

float SweptEllipseTube::normalisedRadius(const Vec3f& p, TubeSection* nearest) const {
  size_t bestIndex = 0;
  float best = std::numeric_limits<float>::infinity();
  for (size_t k = 0; k < dense_.size(); ++k) {
    const float d2 = (p - dense_[k].center).squaredNorm();
    if (d2 < best) {
      best = d2;
      bestIndex = k;
    }
  }
  const TubeSection& s = dense_[bestIndex];
  if (nearest) *nearest = s;
  const Vec3f q = p - s.center;
  const float a = q.dot(s.e1) / s.halfWidth, b = q.dot(s.e2) / s.halfDepth;
  // Beyond an end: the rounded cap, a half-ellipsoid reaching capLength() past the end section.
  const float axial = q.dot(s.tangent);
  const bool beyond = (bestIndex == 0 && axial < 0.f) || (bestIndex + 1 == dense_.size() && axial > 0.f);
  const float c = beyond ? axial / capLength(s) : 0.f;
  return std::sqrt(a * a + b * b + c * c);
}

bool SweptEllipseTube::pushOut(Vec3f& p, float clearance) const {
  TubeSection s;
  const float rho = normalisedRadius(p, &s);
  const float target = 1.f + clearance / std::min({s.halfWidth, s.halfDepth, capLength(s)});
  if (rho >= target) return false;
  const Vec3f q = p - s.center;
  const float axial = q.dot(s.tangent);
  const bool beyond =
      (s.param <= dense_.front().param && axial < 0.f) || (s.param >= dense_.back().param && axial > 0.f);
  if (rho < 1e-4f) {  // on the axis: any way out
    p = s.center + s.e1 * s.halfWidth * target;
    return true;
  }
  if (beyond) {
    p = s.center + q * (target / rho);  // scale within the cap's ellipsoid
  } else {
    const Vec3f radial = q - axial * s.tangent;
    p = s.center + axial * s.tangent + radial * (target / rho);
  }
  return true;
}

TubeSection SweptEllipseTube::sectionAtHeight(float y) const {
  for (size_t k = 0; k + 1 < dense_.size(); ++k) {
    const float y0 = dense_[k].center.y(), y1 = dense_[k + 1].center.y();
    if ((y >= y0 && y <= y1) || (y <= y0 && y >= y1)) {
      const float t = y1 != y0 ? (y - y0) / (y1 - y0) : 0.f;
      return section(dense_[k].param + t * (dense_[k + 1].param - dense_[k].param));
    }
  }
  throw Error("swept-ellipse tube: height " + std::to_string(y) + " is outside the part");
}

}  // namespace swish::bake
