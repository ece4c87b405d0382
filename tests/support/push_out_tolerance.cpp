#include "support/push_out_tolerance.hpp"

#include <algorithm>
#include <cmath>

#include "swish/runtime/reference_push_out.hpp"

namespace swish::test {

std::vector<double> pushOutTolerance(const BodyAnchors& anchors, uint32_t sets, std::span<const Mat4f> matrices,
                                     const Points3f& skinned) {
  std::vector<double> out;
  out.reserve(size_t(skinned.size()));
  for (Eigen::Index v = 0; v < skinned.rows(); ++v) {
    Vec3f y = skinned.row(v).transpose();
    double tol = 2e-6 + 1e-5 * double(y.cwiseAbs().maxCoeff());
    for (uint32_t s = 0; s < std::min(sets, anchors.slots()); ++s) {
      const BodyAnchor& an = anchors.slot(s)[size_t(v)];
      if (!an.present()) continue;
      const Vec3f c = runtime::skinAnchorCentre(an, matrices);
      const double tolC = 2e-6 + 1e-5 * double(c.cwiseAbs().maxCoeff()), r = double(an.reach());
      const double e = double((y - c).norm());
      if (e < r) tol = tolC + (e > 0 ? r / e : 1.0) * (tol + tolC) + 1e-5 * r;
      y = runtime::pushedOutOfBall(y, c, an.reach());
    }
    for (int k = 0; k < 3; ++k) out.push_back(tol);
  }
  return out;
}

}  // namespace swish::test
