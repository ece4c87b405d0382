// Core math: rotations and 6D, skeleton FK, skinning and its inverse, tangent frames, the RNG.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"
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

TEST(Skinning, StrongestJointIsTheLargestWeightFirstOfEqualOnes) {
  SkinWeights skin;
  skin.influences = 3;
  skin.joints = {4, 7, 9, 2, 5, 6};
  skin.weights = {0.2f, 0.5f, 0.3f, 0.4f, 0.4f, 0.2f};
  EXPECT_EQ(skin.strongestJoint(0), 7);
  EXPECT_EQ(skin.strongestJoint(1), 2);  // a tie: the first influence
}

TEST(Skinning, UnskinInvertsSkin) {
  Rng rng(test::testSeed(13));
  Model m = test::makeRandomModel(rng);
  const auto mats = m.skeleton.skinningMatrices(test::makeRandomPose(rng, m.skeleton));
  const Points3f posed = skinPositions(m.gameMesh.positions, m.gameMesh.skin, mats);
  const Points3f back = unskinPositions(posed, m.gameMesh.positions, m.gameMesh.skin, mats);
  EXPECT_LT((back - m.gameMesh.positions).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_GT((posed - m.gameMesh.positions).cwiseAbs().maxCoeff(), 1e-3f);  // the pose did move it
}

// The candy wrapper: a vertex half on each of two joints turned 180 degrees apart has a blended
// matrix with two zero singular values, and one turned 170 degrees apart two of cos(85 deg) = 0.087.
// The exact inverse amplifies its offset from the skinned reference 11x (at 170 degrees; without
// bound at 180), the damped one at most 1 / floor = 5x; a vertex on one joint is inverted exactly.
TEST(Skinning, UnskinDampsCollapsedVerticesTowardsTheReference) {
  auto turn = [](float degrees) {
    Mat4f m = Mat4f::Identity();
    m.topLeftCorner<3, 3>() = Eigen::AngleAxisf(degrees * float(M_PI) / 180.f, Vec3f::UnitX()).toRotationMatrix();
    return m;
  };
  SkinWeights skin;
  skin.influences = 2;
  skin.joints = {0, 1, 0, 1, 0, 1};
  skin.weights = {0.5f, 0.5f, 0.5f, 0.5f, 1.f, 0.f};
  Points3f reference(3, 3);
  reference << 0.f, 0.1f, 0.f, 0.f, 0.1f, 0.f, 0.f, 0.1f, 0.f;
  const float floor = UnskinSettings{}.minSingularValue;
  for (const float degrees : {170.f, 180.f}) {
    const std::vector<Mat4f> mats = {Mat4f::Identity(), turn(degrees)};
    // The reference skinned, then moved 5 mm off it in y (the collapsed plane) and 5 mm in x (the axis).
    Points3f posed = skinPositions(reference, skin, mats);
    posed.rowwise() += Eigen::RowVector3f(0.005f, 0.005f, 0.f);
    UnskinStats stats;
    const Points3f back = unskinPositions(posed, reference, skin, mats, {}, &stats);
    EXPECT_EQ(stats.dampedVertices, 2u) << degrees << " degrees";
    const UnskinStats fromPose = collapsedSkinning(skin, mats);  // the same test, without a shape
    EXPECT_EQ(fromPose.dampedVertices, stats.dampedVertices);
    EXPECT_EQ(fromPose.smallestSingularValue, stats.smallestSingularValue);
    EXPECT_LE(stats.smallestSingularValue, std::cos(85.f * float(M_PI) / 180.f) + 1e-4f);
    for (int v = 0; v < 2; ++v) {
      const float offset = (back.row(v) - reference.row(v)).norm();
      EXPECT_TRUE(std::isfinite(offset));
      // x is along the turn's axis (singular value 1, exact: 5 mm); y at most 5x its 5 mm.
      EXPECT_NEAR(back(v, 0) - reference(v, 0), 0.005f, 1e-5f);
      EXPECT_LE(std::abs(back(v, 1) - reference(v, 1)), 0.005f / floor + 1e-5f) << degrees << " degrees";
    }
    // The rigid vertex: exact.
    const Vec3f expected = mats[0].topLeftCorner<3, 3>().inverse() * posed.row(2).transpose();
    EXPECT_LT((back.row(2).transpose() - expected).norm(), 1e-6f);
  }
  // Out of range settings and mismatched sizes are errors, not silent results.
  const std::vector<Mat4f> mats = {Mat4f::Identity(), turn(90.f)};
  EXPECT_THROW(unskinPositions(reference, reference, skin, mats, UnskinSettings{0.f}), Error);
  EXPECT_THROW(unskinPositions(reference, Points3f(2, 3), skin, mats), Error);
}

// A stored shape the bake moves after un-skinning (the cover in the recorded pose, pose_shape.cpp): a vertex
// whose blend collapsed was stored 40 mm off what its pre-skin shape draws (the damped inverse); a 1 mm move
// of it moves it 1 mm at most, never to the drawable shape (un-skinning the whole position did: the corpus's
// torn sleeves). A vertex stored as drawn stays so, moved by exactly its move; unlisted rows stay bitwise.
TEST(Skinning, MovingASkinnedShapeMovesItByTheDrawnMoveOnly) {
  Mat4f half = Mat4f::Identity();
  half.topLeftCorner<3, 3>() = Eigen::AngleAxisf(float(M_PI), Vec3f::UnitX()).toRotationMatrix();
  const std::vector<Mat4f> mats = {Mat4f::Identity(), half};
  SkinWeights skin;
  skin.influences = 2;
  skin.joints = {0, 1, 0, 1, 0, 1};
  skin.weights = {0.5f, 0.5f, 1.f, 0.f, 1.f, 0.f};  // vertex 0 collapsed (180 degrees, half and half)
  Points3f preSkin(3, 3);
  preSkin << 0.f, 0.1f, 0.f, 0.2f, 0.1f, 0.f, 0.4f, 0.1f, 0.f;
  Points3f world = skinPositions(preSkin, skin, mats);
  world(0, 1) += 0.04f;  // not drawable: as the damped un-skinning of a simulated shape leaves it
  const Points3f worldBefore = world, preSkinBefore = preSkin;
  Points3f move = Points3f::Zero(3, 3);
  move.row(0) << 0.f, 0.001f, 0.001f;
  move.row(1) << 0.f, 0.f, 0.002f;
  move.row(2) << 0.f, 0.f, 0.003f;  // not listed: ignored
  moveSkinnedShape(world, preSkin, move, {0, 1}, skin, mats);
  EXPECT_LE((world.row(0) - worldBefore.row(0)).norm(), 0.001f * std::sqrt(2.f) + 1e-6f);
  EXPECT_LT((world.row(1) - worldBefore.row(1) - move.row(1)).norm(), 1e-6f);
  const Points3f drawn = skinPositions(preSkin, skin, mats);
  EXPECT_LT((drawn.row(1) - world.row(1)).norm(), 1e-6f);
  EXPECT_EQ(world.row(2), worldBefore.row(2));
  EXPECT_EQ(preSkin.row(2), preSkinBefore.row(2));
  // The collapsed vertex's pre-skin shape moves by the damped inverse of its move only.
  EXPECT_LE((preSkin.row(0) - preSkinBefore.row(0)).norm(), 0.0015f / UnskinSettings{}.minSingularValue);
  // Mismatched sizes and vertices out of range are errors.
  EXPECT_THROW(moveSkinnedShape(world, preSkin, Points3f::Zero(2, 3), {0}, skin, mats), Error);
  EXPECT_THROW(moveSkinnedShape(world, preSkin, move, {3}, skin, mats), Error);
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

// A quad strip closed into a tube by a UV seam (its first column repeated): welded, only the two rims are
// openings; unwelded, the seam is too.
// A unit square of two triangles: five edges, each once, lower index first, and their lengths.
TEST(Mesh, UniqueEdgesAndTheirLengths) {
  Points3f p(4, 3);
  p << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  const auto edges = uniqueEdges(buildVertexNeighbours(t, 4));
  using E = std::pair<uint32_t, uint32_t>;
  EXPECT_EQ(edges, (std::vector<E>{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {2, 3}}));
  const std::vector<float> l = edgeLengths(p, edges);
  ASSERT_EQ(l.size(), 5u);
  EXPECT_FLOAT_EQ(l[1], std::sqrt(2.f));
  for (size_t e : {0, 2, 3, 4}) EXPECT_FLOAT_EQ(l[e], 1.f) << e;
}

TEST(Mesh, OpenEdgesAreTheRimsOnceTheSeamIsWelded) {
  const int around = 6;
  Points3f p((around + 1) * 2, 3);
  for (int row = 0; row < 2; ++row)
    for (int k = 0; k <= around; ++k) {
      const float a = 2.f * float(M_PI) * float(k % around) / float(around);
      p.row(row * (around + 1) + k) << std::cos(a), float(row), std::sin(a);
    }
  Triangles t(2 * around, 3);
  for (int k = 0; k < around; ++k) {
    const uint32_t a = uint32_t(k), b = a + 1, d = a + uint32_t(around + 1), e = d + 1;
    t.row(2 * k) << a, b, e;
    t.row(2 * k + 1) << a, e, d;
  }
  EXPECT_EQ(openEdges(t).size(), size_t(2 * around + 2));  // the rims and the seam's two sides
  const auto rims = openEdges(trianglesWeldedByPosition(p, t));
  ASSERT_EQ(rims.size(), size_t(2 * around));
  for (const auto& [a, b] : rims) {
    EXPECT_LT(a, b);
    EXPECT_EQ(p(a, 1), p(b, 1));  // along a rim, not across the strip
  }
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
