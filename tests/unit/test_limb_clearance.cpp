// Limb clearance (bake/limb_clearance.hpp): limbs that a recorded pose puts inside the trunk of a body
// made of parts are turned out of it before the garment is simulated.
#include <gtest/gtest.h>

#include <cmath>

#include "swish/bake/body_collider.hpp"
#include "swish/bake/default_character.hpp"
#include "swish/bake/limb_clearance.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"
#include "test_cloth_fixture.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

const Character& mannequin() {
  static const Character c = makeDefaultCharacter();
  return c;
}

// The upper arm `joint` pointing straight down (the mannequin's rest is an A-pose with the arm
// 50 degrees below horizontal, so this turns it about +-Z by 40 degrees), tilted `inward` radians
// towards the body, as in the CMU clips where arms hang against the sides.
Pose armsHanging(const Skeleton& s, float inward) {
  Pose p = s.restPose();
  const float down = 40.f * float(M_PI) / 180.f + inward;
  p.local[size_t(s.find("LeftArm"))] = Quatf(Eigen::AngleAxisf(-down, Vec3f::UnitZ()));
  p.local[size_t(s.find("RightArm"))] = Quatf(Eigen::AngleAxisf(down, Vec3f::UnitZ()));
  return p;
}

// Smallest signed distance from the arm tubes' vertices (farther than 0.1 m from the shoulder joint,
// as the clearance checks them) to the torso, measured independently with a collider over the
// torso alone (the part in front of the chest).
float armToTorso(const Character& c, const Pose& pose) {
  const Mesh& b = c.body;
  Mesh torso = b;
  std::vector<Eigen::Index> keep;
  BodyCollider whole(b, 0.05f);
  whole.pose(c.skeleton.skinningMatrices(c.skeleton.restPose()));
  const int torsoPart = whole.closest(Vec3f(0.f, 1.2f, 0.2f), 0.5f).part;
  for (Eigen::Index t = 0; t < b.triangles.rows(); ++t) {
    const BodyCollider::Hit h = whole.closest(b.positions.row(b.triangles(t, 0)), 1e-4f, torsoPart);
    if (h.found) keep.push_back(t);
  }
  torso.triangles.resize(Eigen::Index(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) torso.triangles.row(Eigen::Index(i)) = b.triangles.row(keep[i]);
  BodyCollider col(torso, 0.05f);
  const auto m = c.skeleton.skinningMatrices(pose);
  col.pose(m);
  const auto rest = c.skeleton.globalTransforms(c.skeleton.restPose());
  float worst = INFINITY;
  for (uint32_t v = 0; v < b.vertexCount(); ++v) {
    const Vec3f x0 = b.positions.row(v);
    if (std::abs(x0.x()) < 0.2f || x0.y() < 0.9f) continue;  // the arms only
    const int shoulder = c.skeleton.find(x0.x() > 0 ? "LeftArm" : "RightArm");
    if ((x0 - rest[size_t(shoulder)].translation).norm() <= 0.1f) continue;
    const Mat4f k = blendedSkinMatrix(b.skin, v, m);
    const Vec3f x = k.topLeftCorner<3, 3>() * x0 + k.topRightCorner<3, 1>();
    const BodyCollider::Hit h = col.closest(x, 0.3f);
    if (h.found) worst = std::min(worst, h.signedDistance);
  }
  return worst;
}

}  // namespace

TEST(LimbClearance, RestPoseOfTheMannequinNeedsNoCorrection) {
  const LimbClearance lc(mannequin());
  EXPECT_EQ(lc.limbCount(), 7u);  // head, two arms, two legs, two feet
  EXPECT_TRUE(lc.skipped().empty()) << lc.skipped();
  Pose p = mannequin().skeleton.restPose();
  EXPECT_TRUE(lc.apply(p).empty());
}

TEST(LimbClearance, HangingArmsAreTurnedOutOfTheTorsoAndNothingElseMoves) {
  const Character& c = mannequin();
  const Skeleton& s = c.skeleton;
  const Pose recorded = armsHanging(s, 0.07f);
  // Measured: the hanging arm tubes are 4-6 cm inside the torso.
  ASSERT_LT(armToTorso(c, recorded), -0.03f);

  LimbClearanceSettings settings;
  const LimbClearance lc(c, settings);
  Pose p = recorded;
  const std::vector<LimbCorrection> fixes = lc.apply(p);
  ASSERT_EQ(fixes.size(), 2u);
  for (const LimbCorrection& f : fixes) {
    EXPECT_TRUE(f.joint == "LeftArm" || f.joint == "RightArm") << f.joint;
    EXPECT_GT(f.depthBefore, 0.03f);
    EXPECT_EQ(f.depthAfter, 0.f);
    EXPECT_GT(f.degrees, 5.f);
    EXPECT_LT(f.degrees, settings.maxDegrees);
  }
  // Out of the torso by the clearance, less the 1 mm the search leaves (checked with another collider).
  EXPECT_GT(armToTorso(c, p), settings.clearance - 0.0011f);
  // Only the two upper arms changed; the spine (the model's inputs) is untouched.
  for (size_t j = 0; j < s.size(); ++j) {
    const bool arm = s.joints[j].name == "LeftArm" || s.joints[j].name == "RightArm";
    EXPECT_EQ(arm, !p.local[j].coeffs().isApprox(recorded.local[j].coeffs())) << s.joints[j].name;
  }
  // The smallest turn: one degree less leaves the arm inside the clearance.
  for (const LimbCorrection& f : fixes) {
    Pose less = p;
    const int j = s.find(f.joint);
    less.local[size_t(j)] = recorded.local[size_t(j)].slerp(1.f - 1.f / f.degrees, p.local[size_t(j)]);
    EXPECT_FALSE(lc.apply(less).empty()) << f.joint;
  }
  // Deterministic.
  Pose again = recorded;
  lc.apply(again);
  for (size_t j = 0; j < s.size(); ++j) EXPECT_EQ(again.local[j].coeffs(), p.local[j].coeffs());
}

TEST(LimbClearance, OnePartBodiesAndBadPosesAreLeftAlone) {
  const Character capsule = test::capsuleCharacter();
  const LimbClearance lc(capsule);
  EXPECT_EQ(lc.limbCount(), 0u);
  EXPECT_NE(lc.skipped().find("one connected mesh"), std::string::npos) << lc.skipped();
  // A trunk with a hole has no inside: nothing is checked.
  Character open = mannequin();
  open.body.triangles.conservativeResize(open.body.triangles.rows(), 3);
  open.body.triangles.row(0) = open.body.triangles.row(1);  // one torso triangle doubled, one gone
  const LimbClearance holed(open);
  EXPECT_EQ(holed.limbCount(), 0u);
  EXPECT_NE(holed.skipped().find("not a closed surface"), std::string::npos) << holed.skipped();
  Pose p = capsule.skeleton.restPose();
  p.local[2] = Quatf(Eigen::AngleAxisf(1.2f, Vec3f::UnitX()));
  EXPECT_TRUE(lc.apply(p).empty());

  Pose bad = armsHanging(mannequin().skeleton, 0.f);
  bad.local[3].x() = NAN;
  const Pose before = bad;
  EXPECT_TRUE(LimbClearance(mannequin()).apply(bad).empty());
  EXPECT_TRUE(bad.local[5].coeffs() == before.local[5].coeffs());

  LimbClearanceSettings wrong;
  wrong.clearance = -1.f;
  EXPECT_THROW(LimbClearance(mannequin(), wrong), Error);
}
