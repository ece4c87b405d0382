// Body coverage (bake/transfer/body_coverage.hpp): the body triangles a garment covers in every pose,
// on the capsule torso and its tube shirt, whose answer is known from the geometry: the cylinder's
// triangles whose centroids lie within the tube's height, and after the tube moves up, only those still
// within it.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

#include "support/cloth_fixture.hpp"
#include "swish/bake/transfer/body_coverage.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

float centroidY(const Mesh& m, uint32_t t) {
  float y = 0.f;
  for (int k = 0; k < 3; ++k) y += m.positions(m.triangles(t, k), 1);
  return y / 3.f;
}

// Two poses of the character at rest: its garment as it is, and the garment moved up by `rise` metres.
std::pair<DatasetPose, DatasetPose> restAndRaised(const Character& ch, float rise) {
  DatasetPose rest;
  rest.id = 0;
  rest.pose = ch.skeleton.restPose();
  rest.gameMeshWorld = ch.garment.positions;
  DatasetPose raised = rest;
  raised.id = 1;
  raised.gameMeshWorld.col(1).array() += rise;
  return {rest, raised};
}

}  // namespace

TEST(BodyCoverage, CoveredInEveryPoseIsWhatTheGarmentHidesInAll) {
  const test::CapsuleSpec spec;  // tube from y 0.05 to 0.62, 12 mm off a 0.12 m capsule
  const Character ch = test::capsuleCharacter(spec);
  const auto [rest, raised] = restAndRaised(ch, 0.1f);  // the shirt ridden up by 10 cm

  const BodyCoverageResult one = coveredBodyTriangles(ch, {&rest});
  EXPECT_EQ(one.bodyTriangles, ch.body.triangleCount());
  EXPECT_EQ(one.poses, 1u);
  EXPECT_EQ(one.coveredAtRest, one.covered.size());
  std::vector<uint8_t> inOne(ch.body.triangleCount(), 0);
  for (uint32_t t : one.covered) inOne[t] = 1;
  // A centroid 1 cm inside the tube's ends is covered, one 1 cm beyond them is not (the rays are
  // radial on the cylinder; the margin covers a triangle's own height of 2.5 cm / 2).
  size_t inside = 0;
  for (uint32_t t = 0; t < ch.body.triangleCount(); ++t) {
    const float y = centroidY(ch.body, t);
    if (y > spec.garmentLow + 0.015f && y < spec.garmentHigh - 0.015f) {
      EXPECT_TRUE(inOne[t]) << t << " y " << y;
      ++inside;
    }
    if (y < spec.garmentLow - 0.015f || y > spec.garmentHigh + 0.015f) {
      EXPECT_FALSE(inOne[t]) << t << " y " << y;
    }
  }
  EXPECT_GT(inside, 100u);

  BodyCoverageOptions every;
  every.minShare = 1.0;
  const BodyCoverageResult both = coveredBodyTriangles(ch, {&rest, &raised}, every);
  EXPECT_EQ(both.poses, 2u);
  EXPECT_EQ(both.coveredAtRest, one.covered.size());
  EXPECT_LT(both.covered.size(), one.covered.size());
  EXPECT_TRUE(std::is_sorted(both.covered.begin(), both.covered.end()));
  for (uint32_t t : both.covered) {
    EXPECT_TRUE(inOne[t]) << "covered in both poses but not in the first: " << t;
    EXPECT_GT(centroidY(ch.body, t), spec.garmentLow + 0.1f - 0.015f) << t;
  }
  // With half the poses enough, the union of the two.
  BodyCoverageOptions half;
  half.minShare = 0.5;
  const BodyCoverageResult either = coveredBodyTriangles(ch, {&rest, &raised}, half);
  EXPECT_GT(either.covered.size(), one.covered.size());
  for (uint32_t t : one.covered) EXPECT_TRUE(std::binary_search(either.covered.begin(), either.covered.end(), t));
  // A body-less character covers nothing.
  Character bare = ch;
  bare.body = Mesh{};
  EXPECT_TRUE(coveredBodyTriangles(bare, {&rest}).covered.empty());
}

// A part buried in another hides its own triangles (BodyCoverageOptions::buriedCounts): a 3 cm cube set
// into the capsule up to its surface (z from 0.09 to 0.12 at y 0.3; the capsule's radius is 0.12, the
// tube's 0.132). At rest the tube covers its outer (+z), inner (-z) and x faces (their normals meet the
// tube; the y faces' run along it and never do); with the tube ridden up 30 cm nothing covers the cube,
// but all faces but the outer one lie inside the capsule. Over both poses the inner and x faces are
// listed; without buriedCounts none of the cube is.
TEST(BodyCoverage, ABuriedPartCountsAsHidden) {
  const test::CapsuleSpec spec;
  Character ch = test::capsuleCharacter(spec);
  Mesh& body = ch.body;
  const Eigen::Index v0 = body.positions.rows(), t0 = body.triangles.rows();
  body.positions.conservativeResize(v0 + 8, 3);
  for (int c = 0; c < 8; ++c)
    body.positions.row(v0 + c) << (c & 1 ? 0.015f : -0.015f), 0.3f + (c & 2 ? 0.015f : -0.015f),
        0.105f + (c & 4 ? 0.015f : -0.015f);
  // Faces as quads, counter-clockwise seen from outside: -z, +z, -y, +y, -x, +x.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  body.triangles.conservativeResize(t0 + 12, 3);
  for (int f = 0; f < 6; ++f) {
    const uint32_t q[4] = {uint32_t(v0 + quads[f][0]), uint32_t(v0 + quads[f][1]), uint32_t(v0 + quads[f][2]),
                           uint32_t(v0 + quads[f][3])};
    body.triangles.row(t0 + 2 * f) << q[0], q[1], q[2];
    body.triangles.row(t0 + 2 * f + 1) << q[0], q[2], q[3];
  }
  const size_t inf = size_t(body.skin.influences);
  for (int c = 0; c < 8; ++c)
    for (size_t i = 0; i < inf; ++i) {
      body.skin.joints.push_back(0);
      body.skin.weights.push_back(i == 0 ? 1.f : 0.f);
    }
  const auto [rest, away] = restAndRaised(ch, 0.3f);

  BodyCoverageOptions every;
  every.minShare = 1.0;
  const BodyCoverageResult r = coveredBodyTriangles(ch, {&rest, &away}, every);
  ASSERT_EQ(r.buriedPerPose.size(), 2u);
  EXPECT_GE(r.buriedPerPose[1], 10u) << "the cube's sides and inner face, and the capsule inside the cube";
  auto listed = [](const BodyCoverageResult& res, Eigen::Index t) {
    return std::binary_search(res.covered.begin(), res.covered.end(), uint32_t(t));
  };
  for (int f = 0; f < 6; ++f)
    for (int k = 0; k < 2; ++k) {
      const Eigen::Index t = t0 + 2 * f + k;
      EXPECT_EQ(listed(r, t), f == 0 || f >= 4) << "cube face " << f;  // -z, -x, +x
    }
  every.buriedCounts = false;
  const BodyCoverageResult plain = coveredBodyTriangles(ch, {&rest, &away}, every);
  for (Eigen::Index t = t0; t < t0 + 12; ++t) EXPECT_FALSE(listed(plain, t)) << t;
  EXPECT_LT(plain.covered.size(), r.covered.size());
}
