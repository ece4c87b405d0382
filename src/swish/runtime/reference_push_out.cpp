#include "swish/runtime/reference_push_out.hpp"

#include <algorithm>
#include <cmath>

#include "swish/core/error.hpp"

namespace swish::runtime {

void poseBodyProxy(const BodyProxy& proxy, std::span<const Mat4f> mats, std::vector<float>& out) {
  for (const BodyCapsule& c : proxy.capsules) {
    if (c.joint >= mats.size())
      throw Error("body proxy: capsule joint " + std::to_string(c.joint) + " but " + std::to_string(mats.size()) +
                  " skinning matrices");
    const Mat4f& m = mats[c.joint];
    const Vec3f a = m.topLeftCorner<3, 3>() * c.a + m.topRightCorner<3, 1>();
    const Vec3f b = m.topLeftCorner<3, 3>() * c.b + m.topRightCorner<3, 1>();
    const Vec3f d = b - a;
    const float lenSq = d.squaredNorm();
    out.insert(out.end(), {a.x(), a.y(), a.z(), c.radius, d.x(), d.y(), d.z(), lenSq > 0.f ? 1.f / lenSq : 0.f});
  }
}

size_t referencePushOut(Points3f& positions, std::span<const float> posed) {
  if (posed.size() % kPosedCapsuleFloats) throw Error("push-out: posed capsules are not 8 floats each");
  const size_t capsules = posed.size() / kPosedCapsuleFloats;
  size_t moved = 0;
  for (Eigen::Index v = 0; v < positions.rows(); ++v) {
    float x = positions(v, 0), y = positions(v, 1), z = positions(v, 2);
    bool pushed = false;
    for (size_t c = 0; c < capsules; ++c) {
      const float* p = posed.data() + c * kPosedCapsuleFloats;
      const float ax = p[0], ay = p[1], az = p[2], r = p[3], dx = p[4], dy = p[5], dz = p[6], inv = p[7];
      const float wx = x - ax, wy = y - ay, wz = z - az;
      const float t = std::clamp(((wx * dx + wy * dy) + wz * dz) * inv, 0.f, 1.f);
      const float qx = ax + dx * t, qy = ay + dy * t, qz = az + dz * t;
      const float ex = x - qx, ey = y - qy, ez = z - qz;
      const float s = (ex * ex + ey * ey) + ez * ez;
      if (s > kMinPushDistanceSq && s < r * r) {
        const float k = r / std::sqrt(s);
        x = qx + ex * k, y = qy + ey * k, z = qz + ez * k;
        pushed = true;
      }
    }
    if (pushed) {
      positions(v, 0) = x, positions(v, 1) = y, positions(v, 2) = z;
      ++moved;
    }
  }
  return moved;
}

}  // namespace swish::runtime
