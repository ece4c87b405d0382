// Animation import: the strict BVH reader, the assimp reader, joint maps and retargeting onto the
// shared test character (A-pose, identity rests) from the CMU T-pose clips.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <assimp/scene.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/io/bvh_reader.hpp"
#include "swish/io/character_import.hpp"

using namespace swish;
namespace fs = std::filesystem;

namespace {

const fs::path kClip = test::debianMocap("01_01.bvh");
const fs::path kCharacter = test::sharedAsset("tshirt_lo.glb");

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

using test::errorOf;

const Character& sharedCharacter() {
  static const Character c = io::importCharacter(kCharacter);
  return c;
}

#define SKIP_WITHOUT_DATA()                                                                         \
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)"; \
  if (!fs::exists(kCharacter)) GTEST_SKIP() << "the shared test character " << kCharacter << " is absent"

}  // namespace

TEST(IoBvh, ReadsCmuClip) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)";
  const io::SourceAnimation a = io::readBvh(kClip);
  EXPECT_EQ(a.jointCount(), 31u);
  EXPECT_EQ(a.jointNames[0], "Hips");
  EXPECT_EQ(a.frames.size(), 2752u);
  EXPECT_NEAR(a.framesPerSecond, 120.0, 0.01);
  EXPECT_EQ(a.parents[size_t(a.find("LeftUpLeg"))], a.find("LHipJoint"));
}

TEST(IoBvh, AgreesWithAssimpsReader) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)";
  const io::SourceAnimation mine = io::readBvh(kClip);
  const io::SourceAnimation theirs = io::readAnimationWithAssimp(kClip, mine.framesPerSecond);
  ASSERT_GE(theirs.frames.size(), 100u);
  for (size_t f : {size_t(0), size_t(57), size_t(99)}) {
    const auto a = mine.frameGlobals(f), b = theirs.frameGlobals(f);
    size_t compared = 0;
    for (size_t j = 0; j < mine.jointCount(); ++j) {
      const int k = theirs.find(mine.jointNames[j]);
      if (k < 0) continue;
      ++compared;
      EXPECT_LT((a[j].translation - b[size_t(k)].translation).norm(), 1e-3f) << mine.jointNames[j] << " frame " << f;
    }
    EXPECT_EQ(compared, 31u);
  }
}

TEST(IoBvh, BadFilesNameFileAndLine) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)";
  const std::string text = readText(kClip);
  {  // truncated in the motion section
    std::istringstream in(text.substr(0, text.size() / 2));
    const std::string e = errorOf([&] { io::readBvh(in, "cut.bvh"); });
    EXPECT_NE(e.find("cut.bvh:"), std::string::npos) << e;
    EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  }
  {  // a NaN in frame data, on a known line
    std::string bad = text;
    const size_t motion = bad.find("Frame Time:");
    const size_t line3 = bad.find('\n', bad.find('\n', bad.find('\n', motion) + 1) + 1) + 1;  // 3rd frame line
    bad.replace(line3, bad.find(' ', line3) - line3, "nan");
    const int lineNo = int(std::count(bad.begin(), bad.begin() + long(line3), '\n')) + 1;
    std::istringstream in(bad);
    const std::string e = errorOf([&] { io::readBvh(in, "nan.bvh"); });
    EXPECT_NE(e.find("nan.bvh:" + std::to_string(lineNo) + ":"), std::string::npos) << e;
    EXPECT_NE(e.find("non-finite"), std::string::npos) << e;
  }
  {  // a broken hierarchy
    std::istringstream in("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0\n");
    const std::string e = errorOf([&] { io::readBvh(in, "h.bvh"); });
    EXPECT_NE(e.find("h.bvh:"), std::string::npos) << e;
  }
  EXPECT_NE(errorOf([] { io::readBvh(fs::path("/no/such/clip.bvh")); }).find("/no/such/clip.bvh"), std::string::npos);
}

TEST(IoJointMap, ConventionsMapOntoCmuNames) {
  Skeleton cmu;
  for (const char* n : {"Hips", "LowerBack", "Spine", "Spine1", "Neck", "LeftArm"})
    cmu.joints.push_back({n, int(cmu.joints.size()) - 1, {}});
  const auto mixamo = io::mapJoints({"mixamorig:Hips", "mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2",
                                     "mixamorig:Neck", "mixamorig:LeftArm"},
                                    cmu);
  EXPECT_EQ(mixamo.naming, io::JointNaming::Mixamo);
  EXPECT_EQ(mixamo.sourceOf[size_t(cmu.find("LowerBack"))], 1);
  EXPECT_EQ(mixamo.sourceOf[size_t(cmu.find("Spine1"))], 3);
  const auto unreal = io::mapJoints({"pelvis", "spine_01", "spine_02", "spine_03", "neck_01", "upperarm_l"}, cmu);
  EXPECT_EQ(unreal.naming, io::JointNaming::Unreal);
  EXPECT_EQ(unreal.mappedCount(), 6u);
  EXPECT_EQ(unreal.sourceOf[size_t(cmu.find("LeftArm"))], 5);
  io::JointMapOptions pairs;
  pairs.explicitPairs = {{"Torso", "Spine"}};
  EXPECT_EQ(io::mapJoints({"Hips", "Torso"}, cmu, pairs).sourceOf[size_t(cmu.find("Spine"))], 1);
}

namespace {

// 01_01.bvh onto a character: finite unit quaternions, moving arms, and the first frame's bones pointing
// where the clip's bones point.
void checkCmuClipRetargetedOnto(const Character& c) {
  io::RetargetReport report;
  const AnimationClip clip = io::importAnimation(kClip, c.skeleton, {}, &report);
  ASSERT_EQ(clip.frames.size(), 2752u);
  EXPECT_EQ(report.mapping.mappedCount(), 31u);
  EXPECT_GT(report.rootTranslationScale, 0.02f);  // CMU units are about 0.056 m
  EXPECT_LT(report.rootTranslationScale, 0.1f);
  for (const Pose& p : clip.frames)
    for (const Quatf& q : p.local) {
      ASSERT_TRUE(q.coeffs().allFinite());
      ASSERT_NEAR(q.norm(), 1.f, 1e-4f);
    }
  // The arms move: the upper arm's local rotation spans a large angle over the clip.
  const size_t arm = size_t(c.skeleton.find("LeftArm"));
  float maxAngle = 0;
  for (const Pose& p : clip.frames)
    maxAngle = std::max(maxAngle, p.local[arm].angularDistance(clip.frames[0].local[arm]));
  EXPECT_GT(maxAngle, 0.3f);

  // Frame 0: every single-child bone of the character points where the clip's bone points.
  const io::SourceAnimation src = io::readBvh(kClip);
  const auto g = c.skeleton.globalTransforms(clip.frames[0]);
  const auto s = src.frameGlobals(0);
  for (const char* pair : {"LeftArm>LeftForeArm", "LeftForeArm>LeftHand", "RightArm>RightForeArm", "LeftUpLeg>LeftLeg",
                           "RightLeg>RightFoot", "Spine>Spine1", "Neck1>Head"}) {
    const std::string p(pair);
    const std::string a = p.substr(0, p.find('>')), b = p.substr(p.find('>') + 1);
    for (const std::string& name : {a, b}) {
      ASSERT_GE(c.skeleton.find(name), 0) << name << " missing from the character";
      ASSERT_GE(src.find(name), 0) << name << " missing from the clip";
    }
    const Vec3f dc =
        (g[size_t(c.skeleton.find(b))].translation - g[size_t(c.skeleton.find(a))].translation).normalized();
    const Vec3f ds = (s[size_t(src.find(b))].translation - s[size_t(src.find(a))].translation).normalized();
    EXPECT_GT(dc.dot(ds), 0.9999f) << a << " -> " << b;
  }
  // Y stays up: the head is above the hips in the first frame.
  EXPECT_GT(g[size_t(c.skeleton.find("Head"))].translation.y(), g[0].translation.y() + 0.4f);
}

}  // namespace

TEST(IoAnimationImport, CmuClipOntoSharedCharacterIsFiniteMovesAndPointsBonesLikeTheClip) {
  SKIP_WITHOUT_DATA();
  checkCmuClipRetargetedOnto(sharedCharacter());
}

TEST(IoAnimationImport, CmuClipOntoDefaultCharacterIsFiniteMovesAndPointsBonesLikeTheClip) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)";
  checkCmuClipRetargetedOnto(bake::makeDefaultCharacter());
}

TEST(IoAnimationImport, UnknownJointsAreAnError) {
  SKIP_WITHOUT_DATA();
  std::string text = readText(kClip);
  for (const char* name : {"LowerBack", "Spine1"}) {
    const size_t at = text.find(std::string("JOINT ") + name);
    text.replace(at + 6, std::strlen(name), std::string("Mystery") + name);
  }
  const test::TempDir tmp("test_unknown");
  const fs::path p = tmp / "clip.bvh";
  std::ofstream(p) << text;
  const std::string e = errorOf([&] { io::importAnimation(p, sharedCharacter().skeleton); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("unknown joints"), std::string::npos) << e;
  EXPECT_NE(e.find("'LowerBack'"), std::string::npos) << e;
}

TEST(IoAnimationImport, GltfClipImportsLikeTheBvhItCameFrom) {
  // No glTF clip ships with the project: let assimp convert the CMU clip to .glb, then check the
  // glTF route (node animation keys, resampling) gives the same motion as the BVH route.
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is absent (Debian package assimp-testmodels)";
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(kClip.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  const test::TempDir tmp("test_clip");
  const fs::path glb = tmp / "clip.glb";
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, "glb2", glb.string()), AI_SUCCESS) << exporter.GetErrorString();
  const Character c = bake::makeDefaultCharacter();
  const AnimationClip fromBvh = io::importAnimation(kClip, c.skeleton);
  io::AnimationImportOptions o;
  o.framesPerSecond = fromBvh.framesPerSecond;
  const AnimationClip fromGltf = io::importAnimation(glb, c.skeleton, o);
  ASSERT_GE(fromGltf.frames.size(), fromBvh.frames.size() - 1);
  float worst = 0;
  for (size_t f = 0; f < fromBvh.frames.size(); f += 97)
    for (size_t j = 0; j < c.skeleton.size(); ++j)
      worst = std::max(worst, fromBvh.frames[f].local[j].angularDistance(fromGltf.frames[f].local[j]));
  EXPECT_LT(worst, 0.01f) << "radians";
}
