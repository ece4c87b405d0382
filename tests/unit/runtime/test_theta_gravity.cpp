// Theta's gravity values (Model::rootGravity, runtime/theta.hpp): the gravity direction in the root
// joint's frame after the input joints' 6D blocks. It follows the body's lean and not its heading.
#include <gtest/gtest.h>

#include <cmath>

#include "swish/core/error.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

std::vector<Quatf> rest(size_t joints) { return std::vector<Quatf>(joints, Quatf::Identity()); }

}  // namespace

TEST(ThetaGravity, FollowsTheLeanNotTheHeading) {
  const std::vector<uint32_t> joints = {2, 1};
  std::vector<Quatf> pose = rest(3);
  pose[1] = Quatf(Eigen::AngleAxisf(0.4f, Vec3f::UnitZ()));
  const std::vector<float> plain = computeTheta(joints, pose);
  const std::vector<float> upright = computeTheta(joints, true, pose);
  ASSERT_EQ(plain.size(), 12u);
  ASSERT_EQ(upright.size(), thetaSize(2, true));
  EXPECT_EQ(std::vector<float>(upright.begin(), upright.begin() + 12), plain);  // the joints' blocks unchanged
  EXPECT_EQ(upright[12], 0.f);
  EXPECT_EQ(upright[13], -1.f);
  EXPECT_EQ(upright[14], 0.f);

  // Turned about +Y (a heading): nothing changes. Leaning 30 degrees forward about +X: gravity in the
  // root's frame is R^-1 (0, -1, 0) = (0, -cos 30, sin 30).
  pose[0] = Quatf(Eigen::AngleAxisf(2.5f, Vec3f::UnitY()));
  const std::vector<float> turned = computeTheta(joints, true, pose);
  EXPECT_NEAR(turned[12], 0.f, 1e-6f);
  EXPECT_NEAR(turned[13], -1.f, 1e-6f);
  EXPECT_NEAR(turned[14], 0.f, 1e-6f);
  pose[0] = Quatf(Eigen::AngleAxisf(float(M_PI / 6), Vec3f::UnitX()));
  const std::vector<float> lean = computeTheta(joints, true, pose);
  EXPECT_NEAR(lean[12], 0.f, 1e-6f);
  EXPECT_NEAR(lean[13], -std::cos(float(M_PI / 6)), 1e-6f);
  EXPECT_NEAR(lean[14], std::sin(float(M_PI / 6)), 1e-6f);
  // The same lean after any heading.
  pose[0] = Quatf(Eigen::AngleAxisf(1.1f, Vec3f::UnitY())) * pose[0];
  const std::vector<float> both = computeTheta(joints, true, pose);
  for (int k = 12; k < 15; ++k) EXPECT_NEAR(both[size_t(k)], lean[size_t(k)], 1e-6f) << k;
}

TEST(ThetaGravity, ABadRootRotationIsReportedInTheSlotAfterTheJoints) {
  const std::vector<uint32_t> joints = {1};
  std::vector<Quatf> pose = rest(2);
  pose[0] = Quatf(std::nanf(""), 0.f, 0.f, 0.f);
  ThetaReport report;
  std::vector<ThetaJointIssue> issues;
  const std::vector<float> theta = computeTheta(joints, true, pose, &report, &issues);
  EXPECT_EQ(report.invalid, 1u);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].skeletonJoint, 0u);
  EXPECT_EQ(issues[0].inputSlot, 1u);
  EXPECT_EQ(theta[7], -1.f);  // the identity stands in: upright
  // Without the gravity values the root is not read at all.
  ThetaReport none;
  computeTheta(joints, false, pose, &none);
  EXPECT_TRUE(none.clean());
  // The output's size must fit.
  std::vector<float> small(6);
  EXPECT_THROW(computeTheta(joints, true, pose, std::span<float>(small)), Error);
}
