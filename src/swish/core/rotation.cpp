#include "swish/core/rotation.hpp"

#include <cmath>

namespace swish {

SanitizedQuat sanitizeQuaternion(const Quatf& q) {
  const Vec4f& c = q.coeffs();
  if (!c.allFinite()) return {Quatf::Identity(), QuatStatus::Invalid};
  const double n =
      std::sqrt(double(c.x()) * c.x() + double(c.y()) * c.y() + double(c.z()) * c.z() + double(c.w()) * c.w());
  if (!(n >= 1e-6) || !std::isfinite(n)) return {Quatf::Identity(), QuatStatus::Invalid};
  Quatf out(float(c.w() / n), float(c.x() / n), float(c.y() / n), float(c.z() / n));
  return {out, std::abs(n - 1.0) > 1e-3 ? QuatStatus::Renormalised : QuatStatus::Ok};
}

Rot6 toRot6(const Mat3f& r) { return {r(0, 0), r(1, 0), r(2, 0), r(0, 1), r(1, 1), r(2, 1)}; }

Rot6 toRot6(const Quatf& q) {
  // Written out instead of q.toRotationMatrix() so the CPU and any GPU port share one formula.
  const float x = q.x(), y = q.y(), z = q.z(), w = q.w();
  return {1.f - 2.f * (y * y + z * z), 2.f * (x * y + w * z),       2.f * (x * z - w * y),
          2.f * (x * y - w * z),       1.f - 2.f * (x * x + z * z), 2.f * (y * z + w * x)};
}

Mat3f rot6ToMatrix(const Rot6& r6) {
  Vec3f a(r6[0], r6[1], r6[2]), b(r6[3], r6[4], r6[5]);
  Vec3f c0 = a.normalized();
  Vec3f c1 = (b - c0.dot(b) * c0).normalized();
  Vec3f c2 = c0.cross(c1);
  Mat3f m;
  m.col(0) = c0;
  m.col(1) = c1;
  m.col(2) = c2;
  return m;
}

Quatf slerpShortest(const Quatf& a, const Quatf& b, float t) {
  Quatf bb = b;
  if (a.dot(b) < 0.f) bb.coeffs() = -b.coeffs();
  return a.slerp(t, bb).normalized();
}

}  // namespace swish
