#include "swish/runtime/reference_push_out.hpp"

#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

Vec3f skinAnchorCentre(const BodyAnchor& an, std::span<const Mat4f> mats) {
  Mat4f b = Mat4f::Zero();
  for (int i = 0; i < kAnchorInfluences; ++i) {
    const float w = an.weights[size_t(i)];
    if (w == 0.f) continue;
    const uint16_t j = an.joints[size_t(i)];
    if (j >= mats.size())
      throw Error("push-out: anchor joint " + std::to_string(j) + " but " + std::to_string(mats.size()) +
                  " skinning matrices");
    b += w * mats[j];
  }
  const Vec3f q = an.centre();
  const Vec3f c0 = b.block<3, 1>(0, 0), c1 = b.block<3, 1>(0, 1), c2 = b.block<3, 1>(0, 2), c3 = b.block<3, 1>(0, 3);
  return ((c0 * q.x() + c1 * q.y()) + c2 * q.z()) + c3;
}

Vec3f pushedOutOfBall(const Vec3f& x, const Vec3f& c, float reach) {
  const float ex = x.x() - c.x(), ey = x.y() - c.y(), ez = x.z() - c.z();
  const float s = (ex * ex + ey * ey) + ez * ez;
  if (!(s > kMinAnchorDistanceSq && s < reach * reach)) return x;
  const float k = reach / std::sqrt(s);
  return Vec3f(c.x() + ex * k, c.y() + ey * k, c.z() + ez * k);
}

size_t referencePushOut(Points3f& positions, const BodyAnchors& anchors, std::span<const Mat4f> mats) {
  if (anchors.empty()) return 0;
  const size_t n = size_t(positions.rows());
  for (uint32_t s = 0; s < anchors.slots(); ++s)
    if (anchors.slot(s).size() != n)
      throw Error("push-out: " + std::to_string(anchors.slot(s).size()) +
                  (s ? std::string(" ") + anchorSlotName(s) : "") + " body anchors for " + std::to_string(n) +
                  " vertices");
  size_t moved = 0;
  for (size_t v = 0; v < n; ++v) {
    const Vec3f x = positions.row(Eigen::Index(v)).transpose();
    Vec3f y = x;
    for (uint32_t s = 0; s < anchors.slots(); ++s) {
      const BodyAnchor& an = anchors.slot(s)[v];
      if (an.present())  // (without one its reach is 0: the kernel computes and keeps the vertex in place)
        y = pushedOutOfBall(y, skinAnchorCentre(an, mats), an.reach());
    }
    if (y == x) continue;
    positions.row(Eigen::Index(v)) = y.transpose();
    ++moved;
  }
  return moved;
}

}  // namespace swish::runtime
