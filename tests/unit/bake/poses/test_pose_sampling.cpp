// Pose sampling: every frame once, Theta layout (6D per joint in the chosen order), mirroring, the
// volume of several virtual characters, and errors.
#include <gtest/gtest.h>

#include "support/random_model.hpp"
#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/core/rotation.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

Skeleton smallSkeleton() {
  Skeleton s;
  auto add = [&](const char* n, int parent, Vec3f t) { s.joints.push_back({n, parent, {Quatf::Identity(), t}}); };
  add("Hips", -1, {0, 1, 0});
  add("LowerBack", 0, {0, 0.1f, 0});
  add("Spine", 1, {0, 0.15f, 0});
  add("Spine1", 2, {0, 0.15f, 0});
  add("LeftArm", 3, {0.2f, 0.1f, 0});
  add("RightArm", 3, {-0.2f, 0.1f, 0});
  s.computeInverseBindFromRest();
  return s;
}

AnimationClip randomClip(const Skeleton& s, size_t frames, uint64_t seed) {
  Rng rng(seed);
  AnimationClip c;
  c.name = "random";
  c.framesPerSecond = 30.f;
  for (size_t f = 0; f < frames; ++f) {
    Pose p = s.restPose();
    for (auto& q : p.local)
      q = Quatf(float(rng.normal()), float(rng.normal()), float(rng.normal()), float(rng.normal())).normalized();
    c.frames.push_back(p);
  }
  return c;
}

}  // namespace

TEST(PoseSampling, EveryFrameOnceWithThetaInJointOrder) {
  const Skeleton s = smallSkeleton();
  const std::vector<AnimationClip> clips{randomClip(s, 40, test::testSeed(1)), randomClip(s, 25, test::testSeed(2))};
  PoseSamplingOptions o;
  o.joints = {"Spine1", "LeftArm"};
  const PoseSamples samples = samplePoses(s, clips, o);
  ASSERT_EQ(samples.dim, 12);
  ASSERT_EQ(samples.size(), 65u);
  ASSERT_EQ(samples.origins.size(), 65u);
  for (size_t i = 0; i < samples.size(); ++i) {
    const auto& o2 = samples.origins[i];
    const size_t frame = size_t(o2.frame);
    ASSERT_EQ(float(frame), o2.frame);
    const Pose& p = clips[o2.clip].frames[frame];
    const Rot6 a = toRot6(p.local[3]), b = toRot6(p.local[4]);
    for (int k = 0; k < 6; ++k) {
      EXPECT_EQ(samples.row(i)[k], a[size_t(k)]);
      EXPECT_EQ(samples.row(i)[6 + k], b[size_t(k)]);
    }
  }
  EXPECT_EQ(samples.origins.back().clip, 1u);
  EXPECT_EQ(samples.origins.back().frame, 24.f);
}

TEST(PoseSampling, SamplesAreTheRuntimeTheta) {
  // The bake measures the rest pose against the samples with runtime::computeTheta (the network's
  // input): each sample must be that vector of its pose.
  const Skeleton s = smallSkeleton();
  const std::vector<AnimationClip> clips{randomClip(s, 12, test::testSeed(7))};
  PoseSamplingOptions o;
  o.joints = {"LeftArm", "LowerBack", "Spine1"};
  const std::vector<uint32_t> joints{uint32_t(s.find("LeftArm")), uint32_t(s.find("LowerBack")),
                                     uint32_t(s.find("Spine1"))};
  const PoseSamples samples = samplePoses(s, clips, o);
  for (size_t f = 0; f < clips[0].frames.size(); ++f) {
    const std::vector<float> x = runtime::computeTheta(joints, clips[0].frames[f].local);
    ASSERT_EQ(x.size(), size_t(samples.dim));
    for (int k = 0; k < samples.dim; ++k)
      EXPECT_NEAR(x[size_t(k)], samples.row(f)[k], 1e-6f) << "frame " << f << " value " << k;
  }
}

TEST(PoseSampling, MirroredCharactersSwapSidesAndReflect) {
  const Skeleton s = smallSkeleton();
  const std::vector<AnimationClip> clips{randomClip(s, 10, test::testSeed(3))};
  PoseSamplingOptions o;
  o.joints = {"LeftArm", "Spine"};
  o.characters = 2;
  o.speedJitter = 0.f;  // character 1 plays the same frames, mirrored
  const PoseSamples samples = samplePoses(s, clips, o);
  ASSERT_EQ(samples.size(), 20u);
  for (size_t i = 0; i < 10; ++i) {
    ASSERT_TRUE(samples.origins[10 + i].mirrored);
    const Pose& p = clips[0].frames[i];
    const Quatf right = p.local[5], spine = p.local[2];
    const Rot6 a = toRot6(Quatf(right.w(), right.x(), -right.y(), -right.z()));
    const Rot6 b = toRot6(Quatf(spine.w(), spine.x(), -spine.y(), -spine.z()));
    for (int k = 0; k < 6; ++k) {
      EXPECT_NEAR(samples.row(10 + i)[k], a[size_t(k)], 1e-6f);
      EXPECT_NEAR(samples.row(10 + i)[6 + k], b[size_t(k)], 1e-6f);
    }
    // poseOfSample gives the full pose the sample stands for.
    const Pose full = poseOfSample(s, clips, samples.origins[10 + i]);
    EXPECT_LT(full.local[4].angularDistance(Quatf(right.w(), right.x(), -right.y(), -right.z())), 1e-5f);
  }
  // Mirroring twice is the identity.
  const Pose twice = mirrorPose(s, mirrorPose(s, clips[0].frames[3]));
  for (size_t j = 0; j < s.size(); ++j) EXPECT_LT(twice.local[j].angularDistance(clips[0].frames[3].local[j]), 1e-6f);
}

TEST(PoseSampling, RecordingVolumeAndDeterminism) {
  const Skeleton s = smallSkeleton();
  const std::vector<AnimationClip> clips{randomClip(s, 50, test::testSeed(4)), randomClip(s, 70, test::testSeed(5))};
  PoseSamplingOptions o;
  o.characters = 5;
  o.secondsPerCharacter = 10.0;
  o.sampleRate = 60.0;
  const PoseSamples a = samplePoses(s, clips, o), b = samplePoses(s, clips, o);
  EXPECT_EQ(a.size(), 5u * 600u);
  EXPECT_EQ(a.dim, 30);
  EXPECT_EQ(a.values, b.values);
  o.seed = 2;
  EXPECT_NE(samplePoses(s, clips, o).values, a.values);
}

TEST(PoseSampling, BadInputIsAnError) {
  const Skeleton s = smallSkeleton();
  std::vector<AnimationClip> clips{randomClip(s, 5, 1)};
  PoseSamplingOptions o;
  o.joints = {"Spine", "Tail"};
  EXPECT_THROW(samplePoses(s, clips, o), Error);
  EXPECT_THROW(samplePoses(s, {}, {}), Error);
  clips[0].frames[2].local.pop_back();
  EXPECT_THROW(samplePoses(s, clips, {}), Error);
}
