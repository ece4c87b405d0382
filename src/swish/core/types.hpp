#pragma once
// Eigen aliases used across swish. Runtime data is float (what the GPU consumes); the bake may use
// double internally where accumulation needs it.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

namespace swish {

using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;
using Vec4f = Eigen::Vector4f;
using Vec3d = Eigen::Vector3d;
using Mat3f = Eigen::Matrix3f;
using Mat4f = Eigen::Matrix4f;
using Mat3d = Eigen::Matrix3d;
using Quatf = Eigen::Quaternionf;
using Quatd = Eigen::Quaterniond;
using VecXf = Eigen::VectorXf;
using VecXd = Eigen::VectorXd;
using MatXf = Eigen::MatrixXf;  // column-major
using MatXd = Eigen::MatrixXd;
// N x 3 row-major: one row per vertex, memory laid out xyzxyz... like a GPU vertex stream.
using Points3f = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Points2f = Eigen::Matrix<float, Eigen::Dynamic, 2, Eigen::RowMajor>;
using Points4f = Eigen::Matrix<float, Eigen::Dynamic, 4, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<uint32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

// A rigid transform kept as rotation + translation (no scale): what skeleton joints carry.
struct RigidTransform {
  Quatf rotation = Quatf::Identity();
  Vec3f translation = Vec3f::Zero();

  Mat4f matrix() const {
    Mat4f m = Mat4f::Identity();
    m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
  }
  RigidTransform operator*(const RigidTransform& o) const {
    return {rotation * o.rotation, rotation * o.translation + translation};
  }
  Vec3f apply(const Vec3f& p) const { return rotation * p + translation; }
  RigidTransform inverse() const {
    Quatf inv = rotation.conjugate();
    return {inv, -(inv * translation)};
  }
};

}  // namespace swish
