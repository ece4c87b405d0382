// The source simulation on the stiff and extreme cases of issue 18, on the default character and on
// the shared T-shirt character: a stiff material (10x the jersey's stretch stiffness), arms raised
// overhead, arms crossed over the chest, a deep forward bend, a twisting spine, 180 degree shoulder
// rotations, and a limb put through the body (the bake's limb clearance turns it out first, as the
// bake does). Each pose goes the bake's way (PoseShapeSimulator::poseToSimulate, then the solver with
// its retry) and must come back as a shape: finite, outside the body, near its equilibrium, not torn.
//
// Resolution: 3000 simulation vertices (the bake's are 6000 and ~12,000), so that the solves stay
// within the suite's budget; the poses and settings are otherwise the bake's.
//
// The bounds are stability bounds, not quality goals: a shape (not a reported failure), finite, no
// vertex inside the body after the final projection, the bulk of the cloth not torn (99th percentile
// edge strain below 70%; an explosion stretches it beyond 100%) and the last frames' motion within
// 50x the equilibrium tolerance. Measured at the time of writing (default character, 3000 vertices):
// the 99th percentile strain was 30-63% and the residual 0.01-0.26 on these poses (arms crossed the
// worst; on the T-shirt they left 6.9 mm inside, pinched between arm and chest; 4.4 mm since its arms are
// turned out of its trunk, session 29), the stiff jersey 35%
// even at rest: far from the goals of issue 18, which these tests do not
// claim. A limb put through the chest stayed 4.5-6.7 cm inside after the clearance's 60 degree turn and
// exploded on both characters (the default character's kept by the 7th attempt with a 767 % tear, the
// T-shirt's on none); since the clearance's turn search (LimbClearanceSettings::turnSearch, session 38)
// clears it, the default character's simulates on the first attempt and the T-shirt's on the 4th (the
// first safer path). The collar-bone lens is kept by the safer paths (ClothSimSettings::saferPathRetries).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/paths.hpp"
#include "support/pose_aim.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/cloth_constraints.hpp"
#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/io/character_import.hpp"

using namespace swish;
using namespace swish::bake;
using test::aim;
using test::childOf;
using test::turnWorld;

namespace {

constexpr size_t kVertices = 3000;
constexpr float kPi = 3.14159265f;

Quatf about(float degrees, const Vec3f& axis) {
  return Quatf(Eigen::AngleAxisf(degrees * kPi / 180.f, axis.normalized()));
}

struct Case {
  std::string name;
  Pose pose;
};

// The extreme poses, in character space (Y up, the character facing +Z, its left side at +X).
std::vector<Case> extremeCases(const Skeleton& sk) {
  std::vector<Case> cases;
  const Pose rest = sk.restPose();
  {
    Pose p = rest;
    aim(sk, p, "LeftArm", Vec3f(0.25f, 1.f, 0.f));
    aim(sk, p, "RightArm", Vec3f(-0.25f, 1.f, 0.f));
    cases.push_back({"arms overhead", p});
  }
  {
    Pose p = rest;
    aim(sk, p, "LeftArm", Vec3f(-0.2f, -0.3f, 1.f));
    aim(sk, p, "RightArm", Vec3f(0.2f, -0.3f, 1.f));
    aim(sk, p, "LeftForeArm", Vec3f(-1.f, 0.1f, 0.2f));
    aim(sk, p, "RightForeArm", Vec3f(1.f, 0.f, 0.3f));
    cases.push_back({"arms crossed over the chest", p});
  }
  {
    Pose p = rest;
    for (const char* j : {"LowerBack", "Spine", "Spine1"}) turnWorld(sk, p, j, about(30.f, Vec3f::UnitX()));
    cases.push_back({"deep forward bend (90 degrees)", p});
  }
  {
    Pose p = rest;
    for (const char* j : {"LowerBack", "Spine", "Spine1"}) turnWorld(sk, p, j, about(30.f, Vec3f::UnitY()));
    cases.push_back({"twisting spine (90 degrees)", p});
  }
  {
    Pose p = rest;
    // The left upper arm twisted 180 degrees about its own bone; the right one swung 170 degrees
    // forwards and up (180 exactly has no shortest way for the transition to take).
    const std::vector<RigidTransform> g = sk.globalTransforms(p);
    const int l = sk.find("LeftArm");
    const Vec3f bone = (g[size_t(childOf(sk, l))].translation - g[size_t(l)].translation).normalized();
    turnWorld(sk, p, "LeftArm", about(179.f, bone));
    turnWorld(sk, p, "RightArm", about(-170.f, Vec3f::UnitX()));
    cases.push_back({"180 degree shoulder rotations", p});
  }
  return cases;
}

// A limb put into and through the chest: the bake's limb clearance turns it out of the trunk first.
Pose limbThroughTheBody(const Skeleton& sk) {
  Pose p = sk.restPose();
  aim(sk, p, "LeftArm", Vec3f(-1.f, -0.4f, 0.1f));
  return p;
}

// A recorded pose that explodes at the bake's resolution (CMU 05_09 frame 183, a dancer's arm raised
// forwards overhead, session 22): the right upper arm 171 degrees from rest and the collar bone raised
// 18 degrees, as the clip has them to 3 decimals (local rotations on top of the rest pose's). Without
// the collar bone, or with it at 10 degrees, the same arm simulates; so does the pose at 3000 vertices.
// With both, the raised collar bone carries the arm tube's root into the torso's shoulder, the two
// parts overlap in a lens there, and the cloth caught in it is pushed out of the arm into the torso at
// one vertex and out of the torso into the arm at its neighbour: edges stretched by 230 to 700 %
// (docs/baking.md, "Two leads measured in session 22").
Pose collarBoneRaisedArmOverhead(const Skeleton& sk) {
  Pose p = sk.restPose();
  const int arm = sk.find("RightArm"), collar = sk.find("RightShoulder");
  p.local[size_t(arm)] = p.local[size_t(arm)] * about(170.8f, Vec3f(0.823f, 0.522f, -0.251f));
  p.local[size_t(collar)] = p.local[size_t(collar)] * about(17.9f, Vec3f(0.064f, 0.643f, -0.771f));
  return p;
}

float strainPercentile99(const ClothSolver& solver, const Points3f& x) {
  const ClothConstraints cc =
      buildClothConstraints(solver.mesh(), solver.mesh().restPositions, solver.settings().material);
  std::vector<float> strain;
  for (const DistanceConstraint& c : cc.stretch) strain.push_back(((x.row(c.i) - x.row(c.j)).norm() - c.rest) / c.rest);
  std::nth_element(strain.begin(), strain.begin() + std::ptrdiff_t(strain.size() * 99 / 100), strain.end());
  return strain[strain.size() * 99 / 100];
}

PoseShapeSettings bakeSettings(float bandFraction) {
  PoseShapeSettings s;
  s.simulationVertices = kVertices;
  s.simulation.attachTopFraction = bandFraction;  // both bake recipes hold the top 3%
  return s;
}

// Returns the attempts the pose took (0 when it failed).
int expectShape(const PoseShapeSimulator& shapes, const Pose& recorded, const std::string& what) {
  const Pose simulated = shapes.poseToSimulate(recorded);
  const PoseSimulation r = shapes.solver().simulate(simulated);
  EXPECT_TRUE(r.ok) << what << ": " << r.failure;
  if (!r.ok) return 0;
  EXPECT_TRUE(r.positions.allFinite()) << what;
  const ClothSimSettings& s = shapes.solver().settings();
  // The final projection moves every vertex out of the body unless two body parts pinch it (arms
  // crossed over the T-shirt's chest left 6.9 mm when this was written): within the failure bound.
  EXPECT_LE(r.residuals.maxPenetration, s.failPenetration) << what;
  EXPECT_GE(r.residuals.equilibriumResidual, 0.f) << what;
  EXPECT_LE(r.residuals.equilibriumResidual, 50.f * s.equilibriumTolerance) << what << ": far from equilibrium";
  const float p99 = strainPercentile99(shapes.solver(), r.positions);
  EXPECT_LT(p99, 0.7f) << what << ": the bulk of the cloth is torn";
  std::printf(
      "%-45s ok after %d attempt(s), residual %.4f, inside %.1f mm, projected %.1f mm, p99 strain %.0f%%, worst edge "
      "%.0f%%, "
      "%.1f s\n",
      what.c_str(), r.attempts, double(r.residuals.equilibriumResidual), 1000.0 * double(r.residuals.maxPenetration),
      1000.0 * double(r.residuals.projectedDepth), 100.0 * double(p99),
      100.0 * double(r.residuals.maxConstraintViolation), r.residuals.seconds);
  if (r.attempts > 1) std::printf("%-45s   first attempt: %s\n", "", r.firstFailure.c_str());
  return r.attempts;
}

void runCases(const Character& ch, float bandFraction, const std::string& who,
              ClothCarry carry = ClothCarry::Skinning) {
  PoseShapeSettings s = bakeSettings(bandFraction);
  s.simulation.carry = carry;
  const PoseShapeSimulator shapes(ch, s);
  for (const Case& c : extremeCases(ch.skeleton)) expectShape(shapes, c.pose, who + ", " + c.name);
}

void runStiff(const Character& ch, float bandFraction, const std::string& who) {
  PoseShapeSettings s = bakeSettings(bandFraction);
  s.simulation.material.name = "jersey x10 stretch";
  s.simulation.material.stretchModulus *= 10.f;
  const PoseShapeSimulator shapes(ch, s);
  Pose p = ch.skeleton.restPose();
  for (const char* j : {"LowerBack", "Spine", "Spine1"}) turnWorld(ch.skeleton, p, j, about(15.f, Vec3f::UnitX()));
  aim(ch.skeleton, p, "LeftArm", Vec3f(0.6f, 1.f, 0.3f));
  expectShape(shapes, ch.skeleton.restPose(), who + ", stiff material, rest");
  expectShape(shapes, p, who + ", stiff material, bend + arm raised");
}

std::filesystem::path tshirtFile() {
  const auto file = test::sharedAsset("tshirt_lo.glb");
  if (!std::filesystem::exists(file) && std::getenv("CI") && std::string(std::getenv("CI")) == "true")
    ADD_FAILURE() << "CI=true but the shared test character is absent: " << file;
  return file;
}

// The collar-bone lens above on the default character at 6000 simulation vertices, the bake's resolution.
int runCollarBoneCase(ClothCarry carry, const std::string& what,
                      std::vector<ClothCarry> retryCarries = {ClothCarry::Skinning}) {
  const Character ch = makeDefaultCharacter();
  PoseShapeSettings s = bakeSettings(0.03f);
  s.simulationVertices = 6000;
  s.simulation.carry = carry;
  s.simulation.retryCarries = std::move(retryCarries);
  const PoseShapeSimulator shapes(ch, s);
  return expectShape(shapes, collarBoneRaisedArmOverhead(ch.skeleton), what);
}

}  // namespace

TEST(ClothExtremePoses, DefaultCharacter) { runCases(makeDefaultCharacter(), 0.03f, "default"); }
TEST(ClothExtremePoses, DefaultCharacterTranslationCarry) {
  runCases(makeDefaultCharacter(), 0.03f, "default, translation carry", ClothCarry::Translation);
}

// The arm aimed through the chest: the push's 60 degree turn left it 66.7 mm inside the torso, and the
// transition exploded at the left upper arm on the first attempt and on both retries; the 7th attempt (the
// cleared path at 2x with the translation carry) kept it with its worst edge stretched 767 % and a vertex
// projected 42 mm. With the turn search the arm is turned clear (in the 60-120 degree range), and the pose
// simulates on the first attempt (measured: p99 strain 32 %, worst edge 70 %, nothing projected, 2.2 s).
// Exactly 1 attempt, so that a change that loses it shows.
TEST(ClothExtremePoses, DefaultCharacterLimbThroughTheBody) {
  const Character ch = makeDefaultCharacter();
  const PoseShapeSimulator shapes(ch, bakeSettings(0.03f));
  EXPECT_EQ(expectShape(shapes, limbThroughTheBody(ch.skeleton), "default, limb through the body"), 1);
}

// With the skinning carry the lens explodes on the first attempt and the skinning retry (at 3000 vertices
// it simulates), on the two cleared paths with the skinning carry and with the dual-quaternion carry; the
// last safer path (attempt 6: 1 + 1 retry + 4), the cleared path at 2x with the translation carry, keeps
// it, as the translation retry does below (measured: p99 strain 12 %, worst edge 32 %, 12 s).
TEST(ClothExtremePoses, DefaultCharacterCollarBoneRaisedArmOverhead) {
  EXPECT_EQ(runCollarBoneCase(ClothCarry::Skinning, "default, collar bone raised, arm overhead"), 6);
}

// The same pose with the translation carry (ClothCarry): the cloth's offsets from its skinned places are
// not turned by blends that disagree in the lens, and it simulates on the first attempt.
TEST(ClothExtremePoses, DefaultCharacterCollarBoneRaisedArmOverheadTranslationCarry) {
  runCollarBoneCase(ClothCarry::Translation, "default, translation carry, collar bone raised");
}

// The skinning carry with both carries on the retry (retryCarries): the first attempt and the skinning
// retry explode as in the disabled case above, the translation retry simulates.
TEST(ClothExtremePoses, DefaultCharacterCollarBoneRaisedArmOverheadTranslationRetry) {
  EXPECT_EQ(runCollarBoneCase(ClothCarry::Skinning, "default, translation retry, collar bone raised",
                              {ClothCarry::Skinning, ClothCarry::Translation}),
            3);
}

TEST(ClothExtremePoses, DefaultCharacterStiffMaterial) { runStiff(makeDefaultCharacter(), 0.03f, "default"); }

TEST(ClothExtremePoses, SharedTshirt) {
  const auto file = tshirtFile();
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared test character absent: " << file;
  runCases(io::importCharacter(file), 0.03f, "T-shirt");
}

// The T-shirt's body is one surface; its arms are turned out of the trunk as skin regions (session 29). The
// arm aimed through the chest exploded near the left upper arm on all 7 attempts while the clearance left it
// inside (disabled as the known gap until session 38); turned clear by the turn search, the first attempt and
// both retries still explode mid-transition (the first at frame 16 of 45, 504 % near the left upper arm: the
// arm's path from the A-pose passes through the trunk) and the first safer path, the transition kept clear
// of the trunk at every frame, keeps it (measured: attempt 4,
// p99 strain 28 %, worst edge 528 %, 3.8 mm projected, 58 s of one core).
TEST(ClothExtremePoses, SharedTshirtLimbThroughTheBody) {
  const auto file = tshirtFile();
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared test character absent: " << file;
  const Character ch = io::importCharacter(file);
  const PoseShapeSimulator shapes(ch, bakeSettings(0.03f));
  EXPECT_EQ(expectShape(shapes, limbThroughTheBody(ch.skeleton), "T-shirt, limb through the body"), 4);
}

TEST(ClothExtremePoses, SharedTshirtStiffMaterial) {
  const auto file = tshirtFile();
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared test character absent: " << file;
  runStiff(io::importCharacter(file), 0.03f, "T-shirt");
}
