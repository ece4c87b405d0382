// The replay planner leaves out what a scene does not need, and the plan really shrinks: fewer GPU
// dispatches, less memory, fewer joints converted to 6D. Its memory figures are the GPU side's own
// (gpu/allocation_plan.hpp; checked against real GpuModel/FrameResources in tests/e2e/test_replay.cpp).
#include <gtest/gtest.h>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/replay/replay_plan.hpp"

namespace {

using namespace swish;
using replay::PlannerOptions;
using replay::planReplay;
using replay::ReplayPlan;
using runtime::Scene;

struct Fixture {
  Model withMaps, withoutMaps;
  std::map<std::string, const Model*> models;
  Fixture() {
    Rng rng(test::testSeed(7));
    test::RandomModelSpec spec;
    spec.joints = 12;
    spec.inputJoints = 3;
    spec.vertices = 200;
    spec.normalMaps = 6;
    spec.mapSize = 32;
    withMaps = test::makeRandomModel(rng, spec);
    spec.normalMaps = 0;
    withoutMaps = test::makeRandomModel(rng, spec);
    models = {{"a.swish", &withMaps}, {"b.swish", &withoutMaps}};
  }
};

Scene sceneOf(const std::vector<std::string>& modelOfCharacter) {
  Scene s;
  s.name = "test";
  s.source = "test.json";
  s.frameCount = 3;
  s.outputs.render = true;
  for (size_t i = 0; i < modelOfCharacter.size(); ++i) {
    runtime::SceneCharacter c;
    c.name = "c" + std::to_string(i);
    c.model = modelOfCharacter[i];
    c.poseStream = "poses.json";
    c.placement.translation = Eigen::Vector3d(double(i), 0, 0);
    s.characters.push_back(c);
  }
  s.validate();
  return s;
}

bool mentions(const ReplayPlan& p, const std::string& text) {
  for (const auto& l : p.leftOut)
    if (l.what.find(text) != std::string::npos || l.why.find(text) != std::string::npos) return true;
  return false;
}

TEST(Planner, CharactersSharingAModelAreOneBatch) {
  Fixture f;
  const ReplayPlan shared = planReplay(sceneOf({"a.swish", "a.swish", "a.swish", "a.swish"}), f.models);
  ASSERT_EQ(shared.batches.size(), 1u);
  EXPECT_EQ(shared.batches[0].characters, (std::vector<uint32_t>{0, 1, 2, 3}));
  // deform, tangents (triangle terms + gather), decode, blend: the same dispatches for all four characters.
  EXPECT_EQ(shared.gpuDispatchesPerFrame(), 5u);
  EXPECT_TRUE(mentions(shared, "3 of 4 per-character dispatches"));
  // Two models: two batches, the model without a database has no normal-map passes.
  const ReplayPlan two = planReplay(sceneOf({"a.swish", "b.swish", "a.swish"}), f.models);
  ASSERT_EQ(two.batches.size(), 2u);
  EXPECT_EQ(two.batches[0].characters, (std::vector<uint32_t>{0, 2}));
  EXPECT_FALSE(two.batches[1].normalMaps);
  EXPECT_EQ(two.gpuDispatchesPerFrame(), 5u + 3u);
  EXPECT_TRUE(mentions(two, "the model has no normal-map database"));
}

TEST(Planner, NoNormalMapOutputDropsLookupDecodeBlendAndTangents) {
  Fixture f;
  Scene full = sceneOf({"a.swish", "a.swish", "a.swish"});
  Scene meshesOnly = full;
  meshesOnly.outputs.render = false;
  meshesOnly.outputs.meshes = true;
  const ReplayPlan a = planReplay(full, f.models), b = planReplay(meshesOnly, f.models);
  EXPECT_EQ(a.gpuDispatchesPerFrame(), 5u);
  EXPECT_EQ(b.gpuDispatchesPerFrame(), 1u);
  EXPECT_FALSE(b.batches[0].normalMaps);
  EXPECT_FALSE(b.batches[0].tangentFrames);
  for (const auto& s : b.stages) {
    EXPECT_EQ(s.name.find("nearest code"), std::string::npos);
    EXPECT_EQ(s.name.find("VQ"), std::string::npos);
    EXPECT_EQ(s.name.find("tangents"), std::string::npos);
  }
  for (const auto& alloc : b.allocations) {
    EXPECT_EQ(alloc.name.find("VQ"), std::string::npos) << alloc.name;
    EXPECT_FALSE(alloc.image) << alloc.name;
  }
  // What was saved: at least the per-character maps (3 x 32 x 32 x 4 bytes), decode scratch,
  // normals, tangents and the database.
  const uint64_t n = f.withMaps.gameMesh.vertexCount();
  const uint64_t atLeast = 3 * 32 * 32 * 4 + 3 * 32 * 32 * 2 + 3 * n * 28 + f.withMaps.normalMaps.codebook.size();
  EXPECT_GE(a.gpuBytes(), b.gpuBytes() + atLeast);
  EXPECT_TRUE(mentions(b, "no output wants normal maps"));
  EXPECT_TRUE(mentions(b, "normals + tangents pass"));
  // The naive plan keeps everything.
  PlannerOptions naive;
  naive.leaveOut = false;
  const ReplayPlan c = planReplay(meshesOnly, f.models, naive);
  EXPECT_EQ(c.gpuDispatchesPerFrame(), 5u);
  EXPECT_EQ(c.gpuBytes(), a.gpuBytes());
  EXPECT_TRUE(c.leftOut.empty());
}

TEST(Planner, NoMeshOutputMeansNoGpuWork) {
  Fixture f;
  Scene s = sceneOf({"a.swish", "b.swish"});
  s.outputs.render = false;
  const ReplayPlan p = planReplay(s, f.models);
  EXPECT_FALSE(p.gpuWork);
  EXPECT_EQ(p.gpuDispatchesPerFrame(), 0u);
  EXPECT_EQ(p.gpuBytes(), 0u);
  EXPECT_TRUE(mentions(p, "every GPU pass"));
}

TEST(Planner, OnlyInputJointsGoTo6D) {
  Fixture f;
  const ReplayPlan p = planReplay(sceneOf({"a.swish", "a.swish"}), f.models);
  EXPECT_EQ(p.rot6JointsPerFrame(), 2u * f.withMaps.inputJoints.size());
  EXPECT_LT(p.rot6JointsPerFrame(), 2u * f.withMaps.skeleton.size());
  EXPECT_TRUE(
      mentions(p, "6D conversion of " + std::to_string(f.withMaps.skeleton.size() - f.withMaps.inputJoints.size())));
}

TEST(Planner, OffScreenAndDistantCharactersSkipMeshAndNormalWork) {
  Fixture f;
  Scene s = sceneOf({"a.swish", "a.swish", "a.swish", "a.swish"});
  const ReplayPlan all = planReplay(s, f.models);
  s.characters[1].visible = false;
  s.characters[3].placement.translation = Eigen::Vector3d(500, 0, 0);
  s.cullDistance = 100.0;
  const ReplayPlan culled = planReplay(s, f.models);
  EXPECT_EQ(culled.offScreen, (std::vector<uint32_t>{1, 3}));
  ASSERT_EQ(culled.batches.size(), 1u);
  EXPECT_EQ(culled.batches[0].characters, (std::vector<uint32_t>{0, 2}));
  EXPECT_LT(culled.gpuBytes(), all.gpuBytes());
  EXPECT_EQ(culled.rot6JointsPerFrame(), all.rot6JointsPerFrame() / 2);
  EXPECT_TRUE(mentions(culled, "character 'c1'"));
  EXPECT_TRUE(mentions(culled, "beyond cullDistance"));
  // Every character off screen: no batch, no GPU memory.
  for (auto& c : s.characters) c.visible = false;
  const ReplayPlan none = planReplay(s, f.models);
  EXPECT_TRUE(none.batches.empty());
  EXPECT_EQ(none.gpuBytes(), 0u);
}

TEST(Planner, SharedMapsAreDecodedOncePerFrame) {
  Fixture f;  // 6 maps in the database
  const ReplayPlan p = planReplay(sceneOf(std::vector<std::string>(10, "a.swish")), f.models);
  EXPECT_EQ(p.batches[0].maxDecodedMaps, 6u);
  EXPECT_TRUE(mentions(p, "at least 4 of 10 map decodes"));
}

TEST(Planner, MissingModelIsAnError) {
  Fixture f;
  EXPECT_THROW(planReplay(sceneOf({"c.swish"}), f.models), Error);
}

TEST(Planner, DescribeListsStagesMemoryAndLeftOut) {
  Fixture f;
  Scene s = sceneOf({"a.swish", "a.swish"});
  s.outputs.render = false;
  s.outputs.meshes = true;
  const std::string text = planReplay(s, f.models).describe();
  EXPECT_NE(text.find("deform (PCA + skinning)"), std::string::npos) << text;
  EXPECT_NE(text.find("GPU memory"), std::string::npos) << text;
  EXPECT_NE(text.find("Left out"), std::string::npos) << text;
  EXPECT_NE(text.find("VQ decode and blend"), std::string::npos) << text;
}

}  // namespace
