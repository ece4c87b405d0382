#include "swish/core/skinning.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish {

Mat4f blendedSkinMatrix(const SkinWeights& skin, size_t v, const std::vector<Mat4f>& m) {
  Mat4f b = Mat4f::Zero();
  for (int k = 0; k < skin.influences; ++k) {
    const float w = skin.weights[v * skin.influences + k];
    if (w != 0.f) b += w * m[skin.joints[v * skin.influences + k]];
  }
  return b;
}

Points3f skinPositions(const Points3f& pre, const SkinWeights& skin, const std::vector<Mat4f>& m) {
  Points3f out(pre.rows(), 3);
  for (Eigen::Index v = 0; v < pre.rows(); ++v) {
    const Mat4f b = blendedSkinMatrix(skin, size_t(v), m);
    out.row(v) = (b.topLeftCorner<3, 3>() * pre.row(v).transpose() + b.topRightCorner<3, 1>()).transpose();
  }
  return out;
}

Points3f unskinPositions(const Points3f& posed, const SkinWeights& skin, const std::vector<Mat4f>& m) {
  Points3f out(posed.rows(), 3);
  for (Eigen::Index v = 0; v < posed.rows(); ++v) {
    const Mat4f b = blendedSkinMatrix(skin, size_t(v), m);
    const Mat3f a = b.topLeftCorner<3, 3>();
    const float det = a.determinant();
    if (!(std::abs(det) > 1e-6f))
      throw Error("cannot un-skin vertex " + std::to_string(v) + ": its blended skinning matrix is singular");
    out.row(v) = (a.inverse() * (posed.row(v).transpose() - b.topRightCorner<3, 1>())).transpose();
  }
  return out;
}

}  // namespace swish
