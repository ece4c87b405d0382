#include "swish/core/skinning.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/SVD>

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

namespace {

// The smallest singular value of A is at least |det| / s_max^2 >= |det| / |A|_F^2: a cheap proof that
// the matrix is well conditioned, true for almost every vertex.
bool surelyAboveFloor(const Mat3f& a, float floor) {
  const float frob2 = a.squaredNorm();
  return frob2 > 0.f && std::abs(a.determinant()) >= floor * frob2;
}

void checkFloor(const UnskinSettings& settings) {
  if (!(settings.minSingularValue > 0.f && settings.minSingularValue <= 1.f))
    throw Error("un-skinning: the smallest trusted singular value must be in (0, 1]");
}

}  // namespace

UnskinStats collapsedSkinning(const SkinWeights& skin, const std::vector<Mat4f>& m, const UnskinSettings& settings) {
  checkFloor(settings);
  UnskinStats st;
  for (size_t v = 0; v < skin.vertexCount(); ++v) {
    const Mat3f a = blendedSkinMatrix(skin, v, m).topLeftCorner<3, 3>();
    if (surelyAboveFloor(a, settings.minSingularValue)) continue;
    const float smallest = Eigen::JacobiSVD<Mat3f>(a).singularValues().minCoeff();
    if (smallest >= settings.minSingularValue) continue;
    ++st.dampedVertices;
    st.smallestSingularValue = std::min(st.smallestSingularValue, smallest);
  }
  return st;
}

Points3f unskinPositions(const Points3f& posed, const Points3f& reference, const SkinWeights& skin,
                         const std::vector<Mat4f>& m, const UnskinSettings& settings, UnskinStats* stats) {
  if (reference.rows() != posed.rows())
    throw Error("un-skinning: " + std::to_string(posed.rows()) + " posed positions but " +
                std::to_string(reference.rows()) + " reference positions");
  checkFloor(settings);
  const float floor = settings.minSingularValue;
  UnskinStats st;
  Points3f out(posed.rows(), 3);
  for (Eigen::Index v = 0; v < posed.rows(); ++v) {
    const Mat4f b = blendedSkinMatrix(skin, size_t(v), m);
    const Mat3f a = b.topLeftCorner<3, 3>();
    const Vec3f y = posed.row(v).transpose() - b.topRightCorner<3, 1>();
    if (surelyAboveFloor(a, floor)) {
      out.row(v) = (a.inverse() * y).transpose();
      continue;
    }
    const Eigen::JacobiSVD<Mat3f> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vec3f& s = svd.singularValues();
    if (s.minCoeff() >= floor) {
      out.row(v) = (a.inverse() * y).transpose();
      continue;
    }
    ++st.dampedVertices;
    st.smallestSingularValue = std::min(st.smallestSingularValue, s.minCoeff());
    Vec3f f;
    for (int k = 0; k < 3; ++k) f[k] = s[k] >= floor ? 1.f / s[k] : s[k] / (floor * floor);
    const Vec3f ref = reference.row(v).transpose();
    const Vec3f x = ref + svd.matrixV() * f.asDiagonal() * svd.matrixU().transpose() * (y - a * ref);
    out.row(v) = x.transpose();
  }
  if (stats) *stats = st;
  return out;
}

void moveSkinnedShape(Points3f& world, Points3f& preSkin, const Points3f& move,
                      const std::vector<Eigen::Index>& vertices, const SkinWeights& skin, const std::vector<Mat4f>& m,
                      const UnskinSettings& settings) {
  if (world.rows() != preSkin.rows() || move.rows() != world.rows() || size_t(world.rows()) != skin.vertexCount())
    throw Error("moving a skinned shape: " + std::to_string(world.rows()) + " posed, " +
                std::to_string(preSkin.rows()) + " pre-skin and " + std::to_string(move.rows()) +
                " moved positions for " + std::to_string(skin.vertexCount()) + " skinned vertices");
  for (Eigen::Index v : vertices)
    if (v < 0 || v >= world.rows())
      throw Error("moving a skinned shape: vertex " + std::to_string(v) + " out of range");
  const Points3f drawnBefore = skinPositions(preSkin, skin, m);
  const Points3f moved = unskinPositions(drawnBefore + move, preSkin, skin, m, settings);
  for (Eigen::Index v : vertices) preSkin.row(v) = moved.row(v);
  const Points3f drawn = skinPositions(preSkin, skin, m);
  for (Eigen::Index v : vertices) world.row(v) += drawn.row(v) - drawnBefore.row(v);
}

}  // namespace swish
