// Body coverage (bake/transfer/body_coverage.hpp): the body triangles a garment covers in every pose,
// on the capsule torso and its tube shirt, whose answer is known from the geometry: the cylinder's
// triangles whose centroids lie within the tube's height, and after the tube moves up, only those still
// within it.
#include <gtest/gtest.h>

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

}  // namespace

TEST(BodyCoverage, CoveredInEveryPoseIsWhatTheGarmentHidesInAll) {
  const test::CapsuleSpec spec;  // tube from y 0.05 to 0.62, 12 mm off a 0.12 m capsule
  const Character ch = test::capsuleCharacter(spec);
  DatasetPose rest, raised;
  rest.id = 0;
  rest.pose = ch.skeleton.restPose();
  rest.gameMeshWorld = ch.garment.positions;
  raised = rest;
  raised.id = 1;
  raised.gameMeshWorld.col(1).array() += 0.1f;  // the shirt ridden up by 10 cm

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
    if (y < spec.garmentLow - 0.015f || y > spec.garmentHigh + 0.015f) EXPECT_FALSE(inOne[t]) << t << " y " << y;
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
