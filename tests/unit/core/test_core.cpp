// Core math: rotations and 6D, skeleton FK, skinning and its inverse, tangent frames, the RNG.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/core/rng.hpp"
#include "swish/core/rotation.hpp"
#include "swish/core/skinning.hpp"

using namespace swish;

TEST(Rotation, SixDOfIdentityIsFirstTwoColumns) {
  const Rot6 r = toRot6(Quatf::Identity());
  const Rot6 expect{1, 0, 0, 0, 1, 0};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(r[i], expect[i]);
}

TEST(Rotation, SixDMatchesMatrixColumnsAndRoundTrips) {
  Rng rng(test::testSeed(11));
  for (int i = 0; i < 200; ++i) {
    Quatf q(float(rng.normal()), float(rng.normal()), float(rng.normal()), float(rng.normal()));
    q.normalize();
    const Mat3f m = q.toRotationMatrix();
    const Rot6 a = toRot6(q), b = toRot6(m);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(a[k], b[k], 2e-6f);
    EXPECT_LT((rot6ToMatrix(a) - m).cwiseAbs().maxCoeff(), 1e-5f);
  }
}

TEST(Rotation, SanitizeFollowsTheDocumentedPolicy) {
  EXPECT_EQ(sanitizeQuaternion(Quatf::Identity()).status, QuatStatus::Ok);
  auto r = sanitizeQuaternion(Quatf(2, 0, 0, 0));
  EXPECT_EQ(r.status, QuatStatus::Renormalised);
  EXPECT_FLOAT_EQ(r.q.w(), 1.f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(sanitizeQuaternion(Quatf(nan, 0, 0, 0)).status, QuatStatus::Invalid);
  EXPECT_EQ(sanitizeQuaternion(Quatf(0, 0, 0, 0)).status, QuatStatus::Invalid);
  EXPECT_EQ(sanitizeQuaternion(Quatf(std::numeric_limits<float>::infinity(), 0, 0, 0)).status, QuatStatus::Invalid);
  EXPECT_TRUE(sanitizeQuaternion(Quatf(nan, 0, 0, 0)).q.isApprox(Quatf::Identity()));
}

TEST(Skeleton, RestPoseSkinningMatricesAreIdentity) {
  Rng rng(test::testSeed(12));
  Model m = test::makeRandomModel(rng);
  for (const Mat4f& s : m.skeleton.skinningMatrices(m.skeleton.restPose()))
    EXPECT_LT((s - Mat4f::Identity()).cwiseAbs().maxCoeff(), 1e-6f);
}

TEST(Skeleton, ChildFollowsParentRotation) {
  Skeleton sk;
  sk.joints.push_back({"root", -1, {Quatf::Identity(), Vec3f(0, 0, 0)}});
  sk.joints.push_back({"child", 0, {Quatf::Identity(), Vec3f(1, 0, 0)}});
  Pose p = sk.restPose();
  p.local[0] = Quatf(Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitZ()));
  auto g = sk.globalTransforms(p);
  EXPECT_LT((g[1].translation - Vec3f(0, 1, 0)).norm(), 1e-6f);
  sk.joints[1].parent = 1;
  EXPECT_THROW(sk.validate(), Error);
}

TEST(Skinning, UnskinInvertsSkin) {
  Rng rng(test::testSeed(13));
  Model m = test::makeRandomModel(rng);
  const auto mats = m.skeleton.skinningMatrices(test::makeRandomPose(rng, m.skeleton));
  const Points3f posed = skinPositions(m.gameMesh.positions, m.gameMesh.skin, mats);
  const Points3f back = unskinPositions(posed, m.gameMesh.skin, mats);
  EXPECT_LT((back - m.gameMesh.positions).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_GT((posed - m.gameMesh.positions).cwiseAbs().maxCoeff(), 1e-3f);  // the pose did move it
}

TEST(MeshFrames, FlatGridHasUnitFramesAlongUvAxes) {
  // A flat grid in the XY plane with u along +x and v along +y: normal +z, tangent +x, sign +1.
  Points3f p(4, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  Points2f uv(4, 2);
  uv << 0, 0, 1, 0, 0, 1, 1, 1;
  Triangles t(2, 3);
  t << 0, 1, 2, 1, 3, 2;
  Points3f n;
  Points4f tan;
  computeVertexFrames(p, uv, t, buildFrameTopology(t, p), n, tan);
  for (int v = 0; v < 4; ++v) {
    EXPECT_LT((n.row(v) - Eigen::RowVector3f(0, 0, 1)).norm(), 1e-6f);
    EXPECT_LT((tan.row(v) - Eigen::RowVector4f(1, 0, 0, 1)).norm(), 1e-6f);
  }
  // Mirrored UVs flip the bitangent sign.
  uv.col(1) = 1.f - uv.col(1).array();
  computeVertexFrames(p, uv, t, buildFrameTopology(t, p), n, tan);
  EXPECT_EQ(tan(0, 3), -1.f);
}

TEST(MeshFrames, SeamCopiesShareTheirNormal) {
  // Two triangles folded at 90 degrees whose shared edge is split into copies (a UV seam).
  Points3f p(6, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0, /* copies */ 0, 0, 0, 0, 1, 0, 0, 0, 1;
  Points2f uv = Points2f::Random(6, 2);
  Triangles t(2, 3);
  t << 0, 1, 2, 3, 4, 5;
  Points3f n;
  Points4f tan;
  computeVertexFrames(p, uv, t, buildFrameTopology(t, p), n, tan);
  EXPECT_LT((n.row(0) - n.row(3)).norm(), 1e-6f);
  EXPECT_LT((n.row(2) - n.row(4)).norm(), 1e-6f);
  EXPECT_GT((n.row(1) - n.row(5)).norm(), 0.5f);  // unshared corners keep their own face normal
}

TEST(Rng, SameSeedSameStreamAndUniformInRange) {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    differs |= x != c.next();
    const double u = a.uniform();
    b.uniform();
    c.uniform();
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
  EXPECT_TRUE(differs);
  EXPECT_LT(Rng(7).below(10), 10u);
}

TEST(Model, RandomModelValidatesAndBrokenOnesDoNot) {
  Rng rng(test::testSeed(14));
  Model m = test::makeRandomModel(rng);
  EXPECT_NO_THROW(m.validate());
  Model bad = m;
  bad.normalMaps.indices[0] = uint16_t(bad.normalMaps.codebookSize);
  EXPECT_THROW(bad.validate(), Error);
  bad = m;
  bad.mlp.layers[1].weight.resize(3, 3);
  EXPECT_THROW(bad.validate(), Error);
  bad = m;
  bad.inputJoints.push_back(9999);
  EXPECT_THROW(bad.validate(), Error);
}
