// Part 1's pose plan (no simulation): growing a bake's pose list (part1.thinning.grow_from) keeps the
// smaller bake's poses, rest pose included, with the same ids and the same simulation fingerprints, so
// a re-run simulates only the poses it adds; synthesized poses (part1.synthesis) likewise come after the
// recorded ones.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/paths.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

const fs::path kClip = test::debianMocap("01_01.bvh");

DatasetBuildSettings settings(const nlohmann::json& thinning, const nlohmann::json& synthesis = nullptr) {
  nlohmann::json recipe = {{"name", "grow"},
                           {"output", "grow"},
                           {"part1",
                            {{"character", "default"},
                             {"clips", {kClip.string()}},
                             {"thinning", thinning},
                             {"simulation", {{"vertices", 0}, {"threads", 2}}}}}};
  if (!synthesis.is_null()) recipe["part1"]["synthesis"] = synthesis;
  return *parseBakeConfig(recipe, "recipe.json", fs::current_path()).part1;
}

}  // namespace

TEST(Part1Plan, GrowingAPoseListKeepsItsPosesAndTheirSimulations) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  const DatasetPosePlan small = planDatasetPoses(settings({{"target_poses", 20}}), {});
  const DatasetPosePlan grown = planDatasetPoses(settings({{"target_poses", 60}, {"grow_from", 20}}), {});
  ASSERT_TRUE(small.result.restPoseAdded);  // 01_01 holds no A-pose: the rest pose is pose 20 or so
  EXPECT_TRUE(grown.result.restPoseAdded);
  const size_t n = small.toSimulate.size();
  EXPECT_NEAR(double(n), 21.0, 1.0);
  EXPECT_NEAR(double(grown.toSimulate.size()), 61.0, 3.0);
  ASSERT_GT(grown.toSimulate.size(), n);

  const std::vector<uint64_t> a = small.poseFingerprints(), b = grown.poseFingerprints();
  ASSERT_EQ(b.size(), grown.toSimulate.size());
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(a[i], b[i]) << "pose " << i << " of the smaller bake simulates again";
    EXPECT_EQ(grown.result.origins[i], small.result.origins[i]) << "pose " << i;
  }
  EXPECT_EQ(small.settingsJson["rest_pose_id"], grown.settingsJson["rest_pose_id"]);
  EXPECT_EQ(grown.result.origins[small.settingsJson["rest_pose_id"].get<size_t>()]["clip"], "rest pose");
  // The added poses are new ones, at the smaller tolerance the larger count needs.
  for (size_t i = n; i < b.size(); ++i)
    for (size_t j = 0; j < n; ++j) EXPECT_NE(b[i], a[j]) << "pose " << i << " repeats pose " << j;
  EXPECT_LT(grown.result.tolerance, small.result.tolerance);
  // The dataset records the growth (a different pose list: its files are rebuilt, its simulations kept).
  EXPECT_EQ(grown.settingsJson["thinning"]["grow_from"], 20);
  EXPECT_FALSE(small.settingsJson["thinning"].contains("grow_from"));

  // Which limbs the clearance turned out of the trunk, per joint: 01_01 hangs its arms, which the
  // mannequin's arm tubes cannot do outside its torso. Every corrected pose names at least one joint.
  const auto& byJoint = grown.result.correctionsByJoint;
  ASSERT_FALSE(byJoint.empty());
  size_t sum = 0;
  for (const auto& [joint, c] : byJoint) {
    EXPECT_GT(c.poses, 0u) << joint;
    EXPECT_LE(c.poses, grown.result.posesCorrected) << joint;
    EXPECT_GT(c.meanDegrees, 0.0) << joint;
    EXPECT_LE(c.meanDegrees, c.maxDegrees) << joint;
    EXPECT_LE(c.maxDegrees, double(grown.result.maxCorrectionDegrees) + 1e-6) << joint;
    sum += c.poses;
  }
  EXPECT_GE(sum, grown.result.posesCorrected);
  EXPECT_TRUE(byJoint.count("LeftArm") + byJoint.count("RightArm") > 0);
  EXPECT_EQ(grown.result.toJson()["corrections_by_joint"].size(), byJoint.size());

  // Evenly spaced frames (the held-out subjects' dataset, made from the same settings) are not thinned,
  // so there is nothing to grow: the frames as asked.
  DatasetBuildSettings even = settings({{"target_poses", 60}, {"grow_from", 20}});
  even.evenPoses = 30;
  const DatasetPosePlan evenPlan = planDatasetPoses(even, {});
  EXPECT_EQ(evenPlan.toSimulate.size(), 30u);
  EXPECT_FALSE(evenPlan.settingsJson["thinning"].contains("grow_from"));
}

TEST(Part1Plan, SynthesizedPosesComeAfterTheRecordedOnesWhichKeepTheirSimulations) {
  if (!fs::exists(kClip)) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  const nlohmann::json thinning = {{"target_poses", 30}};
  const DatasetPosePlan plain = planDatasetPoses(settings(thinning), {});
  const DatasetPosePlan synth = planDatasetPoses(
      settings(thinning, {{"joints", {"LeftShoulder", "RightShoulder"}}, {"poses", 12}, {"seed", 3}}), {});
  const size_t n = plain.toSimulate.size();
  ASSERT_GT(synth.toSimulate.size(), n);
  EXPECT_EQ(synth.result.synthesizedPoses, synth.toSimulate.size() - n);
  EXPECT_NEAR(double(synth.result.synthesizedPoses), 12.0, 2.0);
  EXPECT_EQ(synth.result.synthesisCandidates, 96u);
  const std::vector<uint64_t> a = plain.poseFingerprints(), b = synth.poseFingerprints();
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(a[i], b[i]) << "recorded pose " << i << " simulates again";
    EXPECT_EQ(synth.result.origins[i], plain.result.origins[i]) << "pose " << i;
  }
  // Each added pose names its base and the donors of its two clavicles, and is a new pose.
  for (size_t i = n; i < b.size(); ++i) {
    const nlohmann::json& o = synth.result.origins[i];
    ASSERT_TRUE(o.contains("synthesized")) << o.dump();
    EXPECT_EQ(o["clip"], "01_01");
    ASSERT_EQ(o["synthesized"].size(), 2u);
    EXPECT_EQ(o["synthesized"][0]["joint"], "LeftShoulder");
    EXPECT_EQ(o["synthesized"][1]["joint"], "RightShoulder");
    for (const auto& d : o["synthesized"]) EXPECT_TRUE(d["t"].get<double>() >= -0.25 && d["t"].get<double>() <= 1.25);
    for (size_t j = 0; j < n; ++j) EXPECT_NE(b[i], a[j]) << "pose " << i << " repeats recorded pose " << j;
  }
  // The dataset records the synthesis (another pose list: its files are rebuilt, its simulations kept);
  // without it the settings are as they were, and the held-out subjects' evenly spaced frames get none.
  EXPECT_EQ(synth.settingsJson["synthesis"]["poses"], 12);
  EXPECT_EQ(synth.settingsJson["synthesized_from_id"], n);  // part 2 never holds these out
  EXPECT_FALSE(plain.settingsJson.contains("synthesis"));
  EXPECT_FALSE(plain.settingsJson.contains("synthesized_from_id"));
  DatasetBuildSettings even = settings(thinning, {{"joints", {"LeftShoulder"}}, {"poses", 12}});
  even.evenPoses = 20;
  const DatasetPosePlan evenPlan = planDatasetPoses(even, {});
  EXPECT_EQ(evenPlan.toSimulate.size(), 20u);
  EXPECT_EQ(evenPlan.result.synthesizedPoses, 0u);
}
