// Runtime, per-frame CPU side: the frame evaluator (N characters of one model, rotations -> mesh
// weights, selected map, blend factor) against its pieces run one by one.
#include <gtest/gtest.h>

#include <bit>
#include <limits>
#include <vector>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/frame_evaluator.hpp"

using namespace swish;
using namespace swish::runtime;

TEST(RuntimeFrameEvaluator, AgreesWithThePiecesRunOneByOne) {
  const uint64_t seed = test::testSeed(401);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.normalMaps = 16;
  spec.codeDims = 5;
  const Model model = test::makeRandomModel(rng, spec);
  const uint32_t n = 7;
  FrameEvaluator frame(model, n);
  const MlpEvaluator mlp(model, frame.mlp().kernel());
  const NearestCodeSearch search(model.normalMaps.keys, frame.mlp().kernel());
  std::vector<TemporalFilter> filters(n, TemporalFilter(model.temporalFilter.timeConstantSeconds));

  for (int f = 0; f < 5; ++f) {
    std::vector<Pose> poses;
    for (uint32_t c = 0; c < n; ++c) poses.push_back(test::makeRandomPose(rng, model.skeleton, 1.5f));
    const float dt = f == 2 ? 0.f : 1.f / 30;
    const FrameOutput& out = frame.evaluate(std::span<const Pose>(poses), dt);
    ASSERT_EQ(out.meshWeights.size(), size_t(n) * model.meshComponents());
    EXPECT_TRUE(out.jointIssues.empty());
    EXPECT_TRUE(out.nonFiniteCode.empty());
    EXPECT_GE(out.timings.total, out.timings.mlp);
    for (uint32_t c = 0; c < n; ++c) {
      const std::vector<float> theta = computeTheta(model.inputJoints, poses[c].local);
      std::vector<float> lambda(model.lambdaSize());
      mlp.evaluate(theta, lambda);
      for (int k = 0; k < model.meshComponents(); ++k)
        ASSERT_EQ(std::bit_cast<uint32_t>(out.meshWeights[c * model.meshComponents() + k]),
                  std::bit_cast<uint32_t>(lambda[k]));
      const NearestCode r = search.find(mlp.normalCodeOf(lambda));
      EXPECT_EQ(out.mapIndex[c], r.index);
      const BlendStep s = filters[c].step(dt, r.index);
      EXPECT_EQ(out.blendAlpha[c], s.alpha);
      EXPECT_EQ(out.blend[c].firstFrame, f == 0);
    }
  }
}

TEST(RuntimeFrameEvaluator, ReportsBadDataAndKeepsGoing) {
  Rng rng(test::testSeed(402));
  const Model model = test::makeRandomModel(rng);
  const uint32_t n = 3, j = uint32_t(model.skeleton.size());
  FrameEvaluator frame(model, n);
  std::vector<Quatf> rotations(size_t(n) * j, Quatf::Identity());
  const uint32_t joint = model.inputJoints[1];
  rotations[1 * j + joint] = Quatf(std::numeric_limits<float>::quiet_NaN(), 0, 0, 0);
  rotations[2 * j + joint] = Quatf(2, 0, 0, 0);  // w = 2: the identity once renormalised
  const std::vector<float> dts{1.f / 60, -1.f, std::numeric_limits<float>::quiet_NaN()};
  const FrameOutput& out = frame.evaluate(rotations, dts);
  ASSERT_EQ(out.jointIssues.size(), 2u);
  EXPECT_EQ(out.jointIssues[0].character, 1u);
  EXPECT_EQ(out.jointIssues[0].joint.skeletonJoint, joint);
  EXPECT_EQ(out.jointIssues[0].joint.status, QuatStatus::Invalid);
  EXPECT_EQ(out.jointIssues[1].character, 2u);
  EXPECT_EQ(out.jointIssues[1].joint.status, QuatStatus::Renormalised);
  EXPECT_EQ(out.invalidDt, (std::vector<uint32_t>{1, 2}));
  // Character 1's invalid joint became the identity, character 2's was renormalised to it: one pose.
  for (int k = 0; k < model.meshComponents(); ++k) {
    EXPECT_EQ(out.meshWeights[k], out.meshWeights[model.meshComponents() + k]);
    EXPECT_EQ(out.meshWeights[k], out.meshWeights[2 * model.meshComponents() + k]);
  }
  for (float a : out.blendAlpha) EXPECT_EQ(a, 1.f);  // first frame for everyone
  // Next frame: invalid dt means no change, and the issue lists start empty again.
  std::fill(rotations.begin(), rotations.end(), Quatf::Identity());
  const FrameOutput& next = frame.evaluate(rotations, dts);
  EXPECT_TRUE(next.jointIssues.empty());
  EXPECT_GT(next.blendAlpha[0], 0.f);
  EXPECT_EQ(next.blendAlpha[1], 0.f);
  EXPECT_EQ(next.blendAlpha[2], 0.f);
  frame.resetCharacter(2);
  EXPECT_EQ(frame.evaluate(rotations, 0.f).blendAlpha[2], 1.f);
  EXPECT_THROW(frame.resetCharacter(3), Error);
  // Sizes that do not fit are the caller's bug: thrown, not guessed.
  EXPECT_THROW(frame.evaluate(std::span<const Quatf>(rotations).first(rotations.size() - 1), 0.f), Error);
  EXPECT_THROW(frame.evaluate(rotations, std::vector<float>{0.f, 0.f}), Error);
}

TEST(RuntimeFrameEvaluator, ModelWithoutNormalMaps) {
  Rng rng(test::testSeed(403));
  test::RandomModelSpec spec;
  spec.normalMaps = 0;
  const Model model = test::makeRandomModel(rng, spec);
  FrameEvaluator frame(model, 2);
  EXPECT_FALSE(frame.hasNormalMaps());
  const std::vector<Pose> poses(2, model.skeleton.restPose());
  const FrameOutput& out = frame.evaluate(std::span<const Pose>(poses), 0.1f);
  EXPECT_EQ(out.codeDims, 0u);
  EXPECT_EQ(out.mapIndex, (std::vector<uint32_t>{kNoMap, kNoMap}));
  EXPECT_TRUE(out.blend.empty());
  EXPECT_EQ(out.meshWeights.size(), 2u * model.meshComponents());
}
