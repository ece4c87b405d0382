// Limb clearance (bake/poses/limb_clearance.hpp): limbs that a recorded pose puts inside the trunk of a body
// made of parts, or of a body that is one surface (its limbs' skin regions), are turned out of it before the
// garment is simulated.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "support/cloth_fixture.hpp"
#include "support/paths.hpp"
#include "support/pose_aim.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/poses/limb_clearance.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rotation.hpp"
#include "swish/core/skinning.hpp"
#include "swish/io/character_import.hpp"

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
  EXPECT_EQ(lc.limbCount(), 7u);       // head, two arms, two legs, two feet
  EXPECT_FALSE(lc.limbsAreRegions());  // parts of their own: the one-surface path never runs on it
  EXPECT_TRUE(lc.skipped().empty()) << lc.skipped();
  Pose p = mannequin().skeleton.restPose();
  EXPECT_TRUE(lc.apply(p).empty());
}

// Cloth is only pinched where there is cloth: a thigh drawn in towards the other (20 degrees) touches
// the mannequin's crotch, 7 cm below the jersey's hem, and stays as recorded; with the whole trunk kept
// clear (garmentReach 0, the behaviour before) it was turned out. A thigh raised to the belly (90
// degrees, sitting), under the hem, is still turned out.
TEST(LimbClearance, OnlyTheTrunkUnderTheGarmentIsKeptClear) {
  const Character& c = mannequin();
  const Skeleton& s = c.skeleton;
  const int thigh = s.find("LeftUpLeg");
  auto turned = [&](const Vec3f& axis, float degrees) {
    Pose p = s.restPose();
    p.local[size_t(thigh)] = Quatf(Eigen::AngleAxisf(-degrees * float(M_PI) / 180.f, axis));
    return p;
  };
  const LimbClearanceSettings defaults;
  LimbClearanceSettings whole;
  whole.garmentReach = 0.f;
  const LimbClearance underGarment(c, defaults), everywhere(c, whole);
  EXPECT_EQ(everywhere.guardedTriangles(), everywhere.trunkTriangles());
  EXPECT_LT(underGarment.guardedTriangles(), underGarment.trunkTriangles());
  EXPECT_GT(underGarment.guardedTriangles(), underGarment.trunkTriangles() / 2);

  Pose crossing = turned(Vec3f::UnitZ(), 20.f);
  EXPECT_TRUE(underGarment.apply(crossing).empty());
  crossing = turned(Vec3f::UnitZ(), 20.f);
  const std::vector<LimbCorrection> before = everywhere.apply(crossing);
  ASSERT_EQ(before.size(), 1u);
  EXPECT_EQ(before[0].joint, "LeftUpLeg");

  Pose sitting = turned(Vec3f::UnitX(), 90.f);
  const std::vector<LimbCorrection> fixes = underGarment.apply(sitting);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].joint, "LeftUpLeg");
  EXPECT_GT(fixes[0].degrees, 5.f);

  LimbClearanceSettings bad;
  bad.garmentReach = -1.f;
  EXPECT_THROW(LimbClearance(c, bad), Error);
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

// An arm aimed through the chest (the stability case "limb through the body"): the trunk's push at the arm
// points up the chest, and 60 degrees about it leave the arm inside. The turn search (turnSearch) tries the
// other directions around the arm, to twice maxDegrees, and takes the smallest turn that clears it; without
// it (settings recorded before it) the arm stays inside, as it did.
TEST(LimbClearance, AnArmThePushCannotClearIsTurnedTheLeastWayThatDoes) {
  const Character& c = mannequin();
  Pose recorded = c.skeleton.restPose();
  test::aim(c.skeleton, recorded, "LeftArm", Vec3f(-1.f, -0.4f, 0.1f));
  ASSERT_LT(armToTorso(c, recorded), -0.05f) << "the test pose must put the arm through the chest";

  LimbClearanceSettings asBefore;
  asBefore.turnSearch = false;
  Pose old = recorded;
  const std::vector<LimbCorrection> oldFixes = LimbClearance(c, asBefore).apply(old);
  ASSERT_EQ(oldFixes.size(), 1u);
  EXPECT_EQ(oldFixes[0].joint, "LeftArm");
  EXPECT_EQ(oldFixes[0].degrees, asBefore.maxDegrees);
  EXPECT_GT(oldFixes[0].depthAfter, 0.01f) << "the push's turn alone must leave the arm inside";

  const LimbClearanceSettings settings;
  ASSERT_TRUE(settings.turnSearch);
  const LimbClearance lc(c, settings);
  Pose p = recorded;
  const std::vector<LimbCorrection> fixes = lc.apply(p);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].joint, "LeftArm");
  EXPECT_EQ(fixes[0].depthBefore, oldFixes[0].depthBefore);
  EXPECT_EQ(fixes[0].depthAfter, 0.f);
  EXPECT_GT(fixes[0].degrees, settings.maxDegrees);
  EXPECT_LE(fixes[0].degrees, 2.f * settings.maxDegrees);
  EXPECT_GT(armToTorso(c, p), settings.clearance - 0.0011f);  // checked with another collider
  for (size_t j = 0; j < c.skeleton.size(); ++j) {
    if (c.skeleton.joints[j].name != "LeftArm") {
      EXPECT_EQ(p.local[j].coeffs(), recorded.local[j].coeffs()) << c.skeleton.joints[j].name;
    }
  }
  Pose again = p;
  EXPECT_TRUE(lc.apply(again).empty()) << "a cleared pose needs no more";

  // A limb the push's turn clears is turned exactly as without the search.
  const Pose hanging = armsHanging(c.skeleton, 0.07f);
  Pose withSearch = hanging, without = hanging;
  lc.apply(withSearch);
  LimbClearance(c, asBefore).apply(without);
  for (size_t j = 0; j < c.skeleton.size(); ++j) EXPECT_EQ(withSearch.local[j].coeffs(), without.local[j].coeffs());
}

TEST(LimbClearance, OnePartBodiesAndBadPosesAreLeftAlone) {
  const Character capsule = test::capsuleCharacter();
  const LimbClearance lc(capsule);
  EXPECT_EQ(lc.limbCount(), 0u);
  EXPECT_FALSE(lc.checksHead());  // no joint named Head
  EXPECT_NE(lc.skipped().find("one connected mesh"), std::string::npos) << lc.skipped();
  // A trunk with a hole has no inside: nothing is checked.
  Character open = mannequin();
  open.body.triangles.conservativeResize(open.body.triangles.rows(), 3);
  open.body.triangles.row(0) = open.body.triangles.row(1);  // one torso triangle doubled, one gone
  const LimbClearance holed(open);
  EXPECT_EQ(holed.limbCount(), 0u);
  EXPECT_NE(holed.skipped().find("not a closed surface"), std::string::npos) << holed.skipped();
  // Its neck still keeps its range (and nothing else is looked at).
  Pose bowed = open.skeleton.restPose();
  bowed.local[size_t(open.skeleton.find("Neck1"))] = Quatf(Eigen::AngleAxisf(1.6f, Vec3f::UnitX()));
  bowed.local[size_t(open.skeleton.find("Head"))] = Quatf(Eigen::AngleAxisf(1.6f, Vec3f::UnitX()));
  const std::vector<LimbCorrection> neckOnly = holed.apply(bowed);
  ASSERT_EQ(neckOnly.size(), 1u);
  EXPECT_TRUE(neckOnly[0].neckRange);
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

namespace {

// A one-surface body with a head: the capsule stretched to 1.2 m, its joints renamed Hips, LowerBack,
// Neck, Head (0.75 m): the top 0.45 m of the tube and its cap are the head, the rest the body.
struct HeadedCapsule {
  test::CapsuleSpec spec;
  Character character;
  HeadedCapsule() {
    spec.axisHigh = 1.2f;
    spec.rows = 48;
    spec.garmentHigh = 0.6f;
    character = test::capsuleCharacter(spec);
    character.skeleton.joints[2].name = "Neck";
    character.skeleton.joints[3].name = "Head";
  }
};

Pose headBowed(const Skeleton& s, float degrees) {
  Pose p = s.restPose();
  p.local[3] = Quatf(Eigen::AngleAxisf(degrees * float(M_PI) / 180.f, Vec3f::UnitX()));
  return p;
}

// Deepest a head vertex (rest height above 0.81 m: off the blended neck) is inside the body's
// unblended lower tube (below 0.69 m), analytically.
float headInsideBody(const HeadedCapsule& h, const Pose& pose) {
  const Mesh& b = h.character.body;
  const auto m = h.character.skeleton.skinningMatrices(pose);
  float worst = 0.f;
  for (uint32_t v = 0; v < b.vertexCount(); ++v) {
    const Vec3f x0 = b.positions.row(v);
    if (x0.y() < 0.81f) continue;
    const Mat4f k = blendedSkinMatrix(b.skin, v, m);
    const Vec3f x = k.topLeftCorner<3, 3>() * x0 + k.topRightCorner<3, 1>();
    if (x.y() > 0.69f || x.y() < 0.f) continue;
    worst = std::max(worst, h.spec.radius - Vec3f(x.x(), 0.f, x.z()).norm());
  }
  return worst;
}

}  // namespace

TEST(LimbClearance, OneSurfaceHeadBowedIntoTheBodyIsTurnedBackTowardsRest) {
  const HeadedCapsule h;
  const Skeleton& s = h.character.skeleton;
  LimbClearanceSettings noRange;  // the head step alone (the neck range would turn 170 degrees back first)
  noRange.neckRangeDegrees = 0.f;
  const LimbClearance lc(h.character, noRange);
  ASSERT_TRUE(lc.checksHead()) << lc.skipped();
  EXPECT_TRUE(lc.skipped().empty()) << lc.skipped();
  EXPECT_EQ(lc.limbCount(), 0u);
  EXPECT_GT(lc.headVertexCount(), 100u);

  // At rest and slightly bowed the head is clear: untouched.
  for (float deg : {0.f, 8.f}) {
    Pose p = headBowed(s, deg);
    const Pose before = p;
    EXPECT_TRUE(lc.apply(p).empty()) << deg;
    for (size_t j = 0; j < s.size(); ++j) EXPECT_EQ(p.local[j].coeffs(), before.local[j].coeffs());
  }

  // Folded down along the body the head is centimetres inside it.
  const Pose recorded = headBowed(s, 170.f);
  ASSERT_GT(headInsideBody(h, recorded), 0.03f);
  Pose p = recorded;
  const std::vector<LimbCorrection> fixes = lc.apply(p);
  ASSERT_EQ(fixes.size(), 1u);
  const LimbCorrection& f = fixes[0];
  EXPECT_EQ(f.joint, "Head");
  EXPECT_GT(f.depthBefore, 0.03f);
  EXPECT_EQ(f.depthAfter, 0.f);
  EXPECT_GT(f.towardsRest, 0.f);
  EXPECT_LT(f.towardsRest, 1.f);
  // The head turned back by that fraction of its 170 degrees, about the same axis.
  EXPECT_NEAR(f.degrees, 170.f * f.towardsRest, 0.5f);
  const Eigen::AngleAxisf turned(p.local[3]);
  EXPECT_NEAR(turned.angle() * 180.f / float(M_PI), 170.f - f.degrees, 0.5f);
  EXPECT_GT(turned.axis().x(), 0.999f);
  // Out of the body (measured analytically, 1 mm tolerance), and only the head chain moved.
  EXPECT_LT(headInsideBody(h, p), 0.0011f);
  for (size_t j = 0; j < 3; ++j) EXPECT_EQ(p.local[j].coeffs(), recorded.local[j].coeffs()) << s.joints[j].name;
  // The smallest correction: a percent less leaves the head inside.
  Pose less = recorded;
  less.local[3] = slerpShortest(recorded.local[3], s.joints[3].rest.rotation, f.towardsRest - 0.01f);
  EXPECT_FALSE(lc.apply(less).empty());
  // Corrected poses need no more; deterministic.
  Pose again = p;
  EXPECT_TRUE(lc.apply(again).empty());
  Pose twice = recorded;
  lc.apply(twice);
  for (size_t j = 0; j < s.size(); ++j) EXPECT_EQ(twice.local[j].coeffs(), p.local[j].coeffs());
}

TEST(LimbClearance, BodiesOfPartsNeverGetTheHeadStep) {
  // The mannequin's head is a part of its own, kept out of the torso by limb clearance: the one-surface
  // head step (which would change the default bake's simulated poses) is not set up.
  const LimbClearance lc(mannequin());
  EXPECT_FALSE(lc.checksHead());
  EXPECT_EQ(lc.headVertexCount(), 0u);
  Pose p = mannequin().skeleton.restPose();
  const int neck = mannequin().skeleton.find("Neck");
  ASSERT_GE(neck, 0);
  p.local[size_t(neck)] = Quatf(Eigen::AngleAxisf(1.4f, Vec3f::UnitX()));
  for (const LimbCorrection& f : lc.apply(p)) EXPECT_EQ(f.towardsRest, 0.f) << f.joint;
}

// The neck range: a neck chain (Neck, Neck1, Head on the mannequin) turned further from rest than the
// range, all its joints together, is turned back to the range, every joint by the same share; a neck
// within it, and every other joint, is left as recorded.
TEST(LimbClearance, ANeckBeyondItsRangeIsTurnedBackToIt) {
  const Character& c = mannequin();
  const Skeleton& s = c.skeleton;
  auto degreesFromRest = [&](const Pose& p, const char* joint) {
    const size_t j = size_t(s.find(joint));
    const float d = std::min(1.f, std::abs(s.joints[j].rest.rotation.normalized().dot(p.local[j].normalized())));
    return 2.f * std::acos(d) * 180.f / float(M_PI);
  };
  Pose recorded = s.restPose();  // the A-pose: no limb in the torso
  const float bow = 88.f * float(M_PI) / 180.f;
  recorded.local[size_t(s.find("Neck1"))] = Quatf(Eigen::AngleAxisf(bow, Vec3f::UnitX()));
  recorded.local[size_t(s.find("Head"))] = Quatf(Eigen::AngleAxisf(bow, Vec3f::UnitX()));
  const LimbClearance lc(c);  // the default range: 90 degrees
  Pose p = recorded;
  const std::vector<LimbCorrection> fixes = lc.apply(p);
  // First the range (the head joint names the chain), then limb clearance as for any pose: the head,
  // still bowed 90 degrees, is a part in front of the torso, turned out of it at its root, the Neck.
  ASSERT_GE(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].joint, "Head");
  EXPECT_TRUE(fixes[0].neckRange);
  EXPECT_NEAR(fixes[0].degrees, 176.f - 90.f, 0.5f);
  EXPECT_NEAR(fixes[0].towardsRest, 1.f - 90.f / 176.f, 0.01f);
  for (size_t k = 1; k < fixes.size(); ++k) {
    EXPECT_EQ(fixes[k].joint, "Neck");
    EXPECT_FALSE(fixes[k].neckRange);
  }
  EXPECT_NEAR(degreesFromRest(p, "Neck1"), 45.f, 0.5f);  // each by the same share of its 88 degrees
  EXPECT_NEAR(degreesFromRest(p, "Head"), 45.f, 0.5f);
  for (size_t j = 0; j < s.size(); ++j) {
    const std::string& n = s.joints[j].name;
    if (n != "Neck" && n != "Neck1" && n != "Head") {
      EXPECT_EQ(p.local[j].coeffs(), recorded.local[j].coeffs()) << n;
    }
  }
  // Within the range: as recorded.
  Pose within = s.restPose();
  within.local[size_t(s.find("Neck1"))] = Quatf(Eigen::AngleAxisf(0.7f, Vec3f::UnitX()));
  const Pose before = within;
  EXPECT_TRUE(lc.apply(within).empty());
  for (size_t j = 0; j < s.size(); ++j) EXPECT_EQ(within.local[j].coeffs(), before.local[j].coeffs());
  // Range 0: the neck as recorded, however far it turns.
  LimbClearanceSettings off;
  off.neckRangeDegrees = 0.f;
  Pose q = recorded;
  for (const LimbCorrection& f : LimbClearance(c, off).apply(q)) EXPECT_EQ(f.joint, "Neck");  // the head limb only
  EXPECT_EQ(q.local[size_t(s.find("Neck1"))].coeffs(), recorded.local[size_t(s.find("Neck1"))].coeffs());
  EXPECT_EQ(q.local[size_t(s.find("Head"))].coeffs(), recorded.local[size_t(s.find("Head"))].coeffs());
  LimbClearanceSettings bad;
  bad.neckRangeDegrees = -1.f;
  EXPECT_THROW(LimbClearance(c, bad), Error);
}

namespace {

// The shared T-shirt character's body, one closed surface (tests/support/paths.hpp; skipped when absent).
const Character* tshirtCharacter() {
  static const std::filesystem::path file = test::sharedAsset("tshirt_lo.glb");
  if (!std::filesystem::exists(file)) {
    if (std::getenv("CI") && std::string(std::getenv("CI")) == "true")
      ADD_FAILURE() << "CI=true but the shared test character is absent: " << file;
    return nullptr;
  }
  static const Character c = io::importCharacter(file);
  return &c;
}

// Measured independently of the clearance's own trunk collider: how many samples of the upper arms and
// forearms (vertices whose strongest joint is LeftArm, LeftForeArm or the right ones, farther than 0.1 m
// from the shoulder joint, one per 2 cm cell) lie inside the rest of the body, by the whole closed body's
// winding number (about 1.5 for a point of the surface inside another layer of it, 0.5 on the surface alone).
size_t armSamplesInsideTheBody(const Character& c, const Pose& pose) {
  const Skeleton& s = c.skeleton;
  const Mesh& b = c.body;
  BodyCollider whole(b, 0.05f);
  const auto m = s.skinningMatrices(pose);
  whole.pose(m);
  const auto rest = s.globalTransforms(s.restPose());
  std::vector<std::array<int, 4>> cells;
  size_t inside = 0;
  for (uint32_t v = 0; v < b.vertexCount(); ++v) {
    const std::string& joint = s.joints[b.skin.strongestJoint(v)].name;
    const bool left = joint == "LeftArm" || joint == "LeftForeArm";
    if (!left && joint != "RightArm" && joint != "RightForeArm") continue;
    const Vec3f x0 = b.positions.row(v);
    if ((x0 - rest[size_t(s.find(left ? "LeftArm" : "RightArm"))].translation).norm() <= 0.1f) continue;
    const std::array<int, 4> cell = {int(std::floor(x0.x() / 0.02f)), int(std::floor(x0.y() / 0.02f)),
                                     int(std::floor(x0.z() / 0.02f)), left};
    if (std::find(cells.begin(), cells.end(), cell) != cells.end()) continue;
    cells.push_back(cell);
    const Mat4f k = blendedSkinMatrix(b.skin, v, m);
    const Vec3f x = k.topLeftCorner<3, 3>() * x0 + k.topRightCorner<3, 1>();
    inside += whole.windingNumber(x, whole.closest(x, 0.05f).part) > 1.f;
  }
  return inside;
}

}  // namespace

// A body that is one surface (a MakeHuman body: the shared T-shirt character) has no limb parts: its arms
// and legs are the skin regions of LeftArm, RightArm, LeftUpLeg and RightUpLeg, and arms hanging into its
// sides (as the CMU walks hold them: 4 of 30 unseen poses of the T-shirt exploded there) are turned out as
// a part would be. Bakes recorded before it (limb_one_surface absent: oneSurfaceLimbs false) leave them.
TEST(LimbClearance, OneSurfaceBodyArmsHangingIntoItsSidesAreTurnedOut) {
  const Character* c = tshirtCharacter();
  if (!c) GTEST_SKIP() << "shared test character absent: " << test::sharedAsset("tshirt_lo.glb");
  const Skeleton& s = c->skeleton;
  const LimbClearance lc(*c);
  ASSERT_TRUE(lc.limbsAreRegions()) << lc.skipped();
  EXPECT_EQ(lc.limbCount(), 4u);
  EXPECT_TRUE(lc.checksHead());  // and its head as before
  Pose rest = s.restPose();
  EXPECT_TRUE(lc.apply(rest).empty());

  // The T-shirt's rest rotations are the identity and its arms 50 degrees down, as the mannequin's.
  const Pose recorded = armsHanging(s, 15.f * float(M_PI) / 180.f);
  const size_t before = armSamplesInsideTheBody(*c, recorded);
  ASSERT_GT(before, 10u) << "the test pose must put the arms into the sides";
  Pose p = recorded;
  const std::vector<LimbCorrection> fixes = lc.apply(p);
  std::vector<std::string> turned;
  for (const LimbCorrection& f : fixes) {
    EXPECT_FALSE(f.head || f.neckRange) << f.joint;
    turned.push_back(f.joint);
    EXPECT_GT(f.depthBefore, 0.01f) << f.joint;
    EXPECT_EQ(f.depthAfter, 0.f) << f.joint;
    EXPECT_GT(f.degrees, 15.f) << f.joint;  // at least back to hanging straight down
    EXPECT_LE(f.degrees, 60.f) << f.joint;  // the push's turn, no search
  }
  std::sort(turned.begin(), turned.end());
  EXPECT_EQ(turned, (std::vector<std::string>{"LeftArm", "RightArm"}));
  EXPECT_EQ(armSamplesInsideTheBody(*c, p), 0u) << before << " before";
  // Only the upper arms moved; a corrected pose needs no more; deterministic.
  for (size_t j = 0; j < s.size(); ++j) {
    if (s.joints[j].name != "LeftArm" && s.joints[j].name != "RightArm") {
      EXPECT_EQ(p.local[j].coeffs(), recorded.local[j].coeffs()) << s.joints[j].name;
    }
  }
  Pose again = p;
  for (const LimbCorrection& f : lc.apply(again))
    ADD_FAILURE() << "again: " << f.joint << " " << f.degrees << " deg, " << f.depthBefore << " m before";
  Pose twice = recorded;
  lc.apply(twice);
  for (size_t j = 0; j < s.size(); ++j) EXPECT_EQ(twice.local[j].coeffs(), p.local[j].coeffs());

  LimbClearanceSettings asRecordedBefore;
  asRecordedBefore.oneSurfaceLimbs = false;
  const LimbClearance old(*c, asRecordedBefore);
  EXPECT_FALSE(old.limbsAreRegions());
  EXPECT_EQ(old.limbCount(), 0u);
  Pose asBefore = recorded;
  for (const LimbCorrection& f : old.apply(asBefore)) EXPECT_TRUE(f.head || f.neckRange) << f.joint;
}
