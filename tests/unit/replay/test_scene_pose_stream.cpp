// Pose streams of replay scenes: the file round-trips (NaN as null, missing joints as null), structural
// problems are Errors naming the file and JSON path, and CharacterMotion handles every kind of bad pose
// as character_motion.hpp documents, reporting each with frame, character and joint.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "support/error_message.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/error.hpp"
#include "swish/replay/character_motion.hpp"
#include "swish/replay/pose_stream.hpp"

namespace {

using namespace swish;
namespace fs = std::filesystem;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Skeleton chain3() {
  Skeleton s;
  for (int i = 0; i < 3; ++i) {
    Joint j;
    j.name = "j" + std::to_string(i);
    j.parent = i - 1;
    j.rest.translation = Vec3f(0, i == 0 ? 1.f : 0.2f, 0);
    j.rest.rotation = Quatf(Eigen::AngleAxisf(0.1f * float(i), Vec3f::UnitZ()));
    s.joints.push_back(j);
  }
  s.computeInverseBindFromRest();
  return s;
}

replay::PoseStreamFrame frame(std::vector<Quatf> r, Vec3f root = Vec3f(0, 1, 0)) {
  replay::PoseStreamFrame f;
  f.root = root;
  f.rotations = std::move(r);
  f.present.assign(f.rotations.size(), true);
  return f;
}

TEST(PoseStream, RoundTripsNaNAndMissingJoints) {
  replay::PoseStream s;
  s.framesPerSecond = 24;
  s.joints = {"j0", "j1"};
  s.frames.push_back(frame({Quatf::Identity(), Quatf(kNaN, 0, 0, 1)}));
  s.frames.push_back(frame({Quatf::Identity(), Quatf::Identity()}, Vec3f(kNaN, 0, 0)));
  s.frames[1].present[0] = false;
  const test::TempDir tmp("pose_stream");
  const fs::path f = tmp / "rt.json";
  replay::writePoseStream(f, s);
  const replay::PoseStream r = replay::readPoseStream(f);
  EXPECT_EQ(r.framesPerSecond, 24);
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_TRUE(std::isnan(r.frames[0].rotations[1].w()));
  EXPECT_FLOAT_EQ(r.frames[0].rotations[1].z(), 1.f);
  EXPECT_FALSE(r.frames[1].present[0]);
  EXPECT_TRUE(r.frames[1].present[1]);
  EXPECT_TRUE(std::isnan(r.frames[1].root.x()));
}

TEST(PoseStream, StructuralErrorsNameFileAndPath) {
  const test::TempDir tmp("pose_stream");
  const fs::path f = tmp / "bad.json";
  auto errorOf = [&](const std::string& text, std::source_location where = std::source_location::current()) {
    std::ofstream(f) << text;
    return test::errorOf([&] { replay::readPoseStream(f); }, where);
  };
  EXPECT_NE(errorOf("{").find("not valid JSON"), std::string::npos);
  EXPECT_NE(errorOf(R"({"format": "x", "version": 1})").find("format"), std::string::npos);
  const std::string head = R"({"format": "swish-pose-stream", "version": 1, "joints": ["a"], "frames": )";
  EXPECT_NE(errorOf(head + "[]}").find("frames: must be a non-empty array"), std::string::npos);
  const std::string e = errorOf(head + R"([{"rotations": [[0, 0, 0, 1]]}, {"rotations": [[0, 0, 1]]}]})");
  EXPECT_NE(e.find(f.string()), std::string::npos) << e;
  EXPECT_NE(e.find("frames[1].rotations[0]: must be [x, y, z, w] or null"), std::string::npos) << e;
  EXPECT_NE(errorOf(head + R"([{"rotations": [[0, 0, 0, "w"]]}]})").find("must be a number or null"),
            std::string::npos);
}

TEST(CharacterMotion, BadPosesAreReplacedAndReported) {
  const Skeleton sk = chain3();
  auto s = std::make_shared<replay::PoseStream>();
  s->framesPerSecond = 10;
  s->joints = {"j0", "j1"};  // j2 never named
  const Quatf q = Quatf(Eigen::AngleAxisf(0.5f, Vec3f::UnitX()));
  s->frames.push_back(frame({q, q}));
  s->frames.push_back(frame({Quatf(kNaN, 0, 0, 0), Quatf(0, 0, 0, 0)}, Vec3f(kNaN, 0, 0)));
  s->frames.push_back(frame({Quatf(2.f * q.coeffs()), q}));
  replay::CharacterMotion m(s, sk, "QB");
  std::vector<replay::PoseIssue> issues;

  Pose p0 = m.poseAt(0.0, 7, issues);
  ASSERT_EQ(issues.size(), 1u);  // j2 missing from the stream, reported once
  EXPECT_EQ(issues[0].frame, 7u);
  EXPECT_EQ(issues[0].character, "QB");
  EXPECT_EQ(issues[0].joint, "j2");
  EXPECT_TRUE(p0.local[2].isApprox(sk.joints[2].rest.rotation));
  EXPECT_TRUE(p0.local[0].isApprox(q));

  issues.clear();
  Pose p1 = m.poseAt(0.1, 8, issues);
  ASSERT_EQ(issues.size(), 3u);  // NaN j0, zero j1, NaN root; j2 not again
  EXPECT_EQ(issues[0].joint, "j0");
  EXPECT_EQ(issues[0].action, "rest rotation");
  EXPECT_EQ(issues[1].joint, "j1");
  EXPECT_EQ(issues[2].action, "last finite root kept");
  EXPECT_TRUE(p1.local[0].isApprox(sk.joints[0].rest.rotation));
  EXPECT_TRUE(p1.local[1].isApprox(sk.joints[1].rest.rotation));
  EXPECT_TRUE(p1.rootTranslation.isApprox(p0.rootTranslation));

  issues.clear();
  Pose p2 = m.poseAt(0.2, 9, issues);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].action, "normalised");
  EXPECT_NEAR(p2.local[0].norm(), 1.f, 1e-6f);
  EXPECT_TRUE(p2.local[0].isApprox(q));

  // Past the end: the last frame is held, said once.
  issues.clear();
  m.poseAt(5.0, 60, issues);
  m.poseAt(6.0, 70, issues);
  // The end (once), and the held frame's non-unit j0 on each of the two frames.
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_NE(issues[0].problem.find("ends after 3 frames"), std::string::npos);
  EXPECT_EQ(issues[1].action, "normalised");
  EXPECT_EQ(issues[2].frame, 70u);
}

TEST(CharacterMotion, ClipWrapsAndInterpolates) {
  const Skeleton sk = chain3();
  auto clip = std::make_shared<AnimationClip>();
  clip->framesPerSecond = 10;
  for (int f = 0; f < 4; ++f) {
    Pose p = sk.restPose();
    p.local[1] = Quatf(Eigen::AngleAxisf(0.2f * float(f), Vec3f::UnitY()));
    p.rootTranslation = Vec3f(0.1f * float(f), 1, 0);
    clip->frames.push_back(p);
  }
  runtime::SceneClip play;
  play.timeOffsetSeconds = 0.1;
  play.speed = 2.0;
  replay::CharacterMotion m(clip, play, sk, "WR");
  std::vector<replay::PoseIssue> issues;
  // t = 0.025 s -> clip time 0.15 s -> halfway between frames 1 and 2.
  const Pose p = m.poseAt(0.025, 0, issues);
  EXPECT_TRUE(issues.empty());
  EXPECT_NEAR(Eigen::AngleAxisf(p.local[1]).angle(), 0.3f, 1e-5f);
  EXPECT_NEAR(p.rootTranslation.x(), 0.15f, 1e-6f);
  // Wrapping: clip time 0.1 + 2 * 0.2 = 0.5 s = 0.1 s into the 0.4 s clip -> frame 1.
  const Pose w = m.poseAt(0.2, 1, issues);
  EXPECT_NEAR(Eigen::AngleAxisf(w.local[1]).angle(), 0.2f, 1e-4f);
}

}  // namespace
