// The bake recipe is validated before any work: unknown keys and out-of-range values are errors that
// name the key; defaults fill what is absent; paths resolve against the config's folder.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/core/error.hpp"
#include "swish/model/model_file.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
// An existing file for the clip lists (not __FILE__: with CCACHE_BASEDIR the compiler sees a relative path).
const std::string kThisFile = (test::sourceDir() / "tests/unit/bake/pipeline/test_bake_config.cpp").string();
std::string errorOf(const nlohmann::json& j) {
  return test::errorOf([&] { parseBakeConfig(j, "recipe.json", "/base"); });
}
}  // namespace

TEST(BakeConfig, DefaultsAndPaths) {
  const BakeConfig c = parseBakeConfig({{"name", "jersey"}, {"output", "out"}, {"train", {{"codebook_size", 2048}}}},
                                       "recipe.json", "/base");
  EXPECT_EQ(c.modelPath(), std::filesystem::path("/base/out/jersey.swish"));
  EXPECT_EQ(c.work, std::filesystem::path("/base/out/work"));
  EXPECT_EQ(c.dataset, std::filesystem::path("/base/out/work/dataset"));
  EXPECT_EQ(c.simulationDir(), std::filesystem::path("/base/out/work/simulation"));
  EXPECT_FALSE(c.part1.has_value());
  EXPECT_EQ(c.train.vq.codebookSize, 2048u);
  EXPECT_EQ(c.train.mlp.hiddenLayers, 5);
  EXPECT_EQ(c.train.mlp.hiddenWidth, 32);
  EXPECT_EQ(c.train.databaseSize, 128);
  EXPECT_EQ(c.train.normalCodeWeight, 1.0);
  EXPECT_EQ(c.train.meshWeightFloor, 0.0);
  const BakeConfig f =
      parseBakeConfig({{"output", "out"}, {"train", {{"mesh_weight_floor", 0.5}}}}, "recipe.json", "/base");
  EXPECT_DOUBLE_EQ(f.train.meshWeightFloor, 0.5);
  EXPECT_DOUBLE_EQ(f.train.toJson()["mesh_weight_floor"].get<double>(), 0.5);
  const BakeConfig w =
      parseBakeConfig({{"output", "out"}, {"train", {{"normal_code_weight", 0.1}}}}, "recipe.json", "/base");
  EXPECT_DOUBLE_EQ(w.train.normalCodeWeight, 0.1);
  EXPECT_DOUBLE_EQ(w.train.toJson()["normal_code_weight"].get<double>(), 0.1);  // what the model's metadata records
  EXPECT_TRUE(w.train.inputJoints.empty());                                     // the dataset's (part 1's) joints
  EXPECT_FALSE(w.train.toJson().contains("input_joints"));
  const BakeConfig j = parseBakeConfig({{"output", "out"}, {"train", {{"input_joints", {"Spine", "LeftForeArm"}}}}},
                                       "recipe.json", "/base");
  EXPECT_EQ(j.train.inputJoints, (std::vector<std::string>{"Spine", "LeftForeArm"}));
  EXPECT_EQ(j.train.toJson()["input_joints"], nlohmann::json({"Spine", "LeftForeArm"}));
  // The push-out's anchors: calibrated unless the recipe says "none" (then recorded; absent by default,
  // so that the fingerprints of earlier bakes stay).
  EXPECT_TRUE(w.train.calibrateAnchors);
  EXPECT_FALSE(w.train.toJson().contains("anchor_calibration"));
  const BakeConfig a =
      parseBakeConfig({{"output", "out"}, {"train", {{"anchor_calibration", "none"}}}}, "recipe.json", "/base");
  EXPECT_FALSE(a.train.calibrateAnchors);
  EXPECT_EQ(a.train.toJson()["anchor_calibration"], "none");
  EXPECT_TRUE(
      parseBakeConfig({{"output", "out"}, {"train", {{"anchor_calibration", "strict"}}}}, "recipe.json", "/base")
          .train.calibrateAnchors);
  // Their margin: 2 mm unless the recipe says (then recorded; absent at the default, likewise).
  EXPECT_FLOAT_EQ(w.train.anchorMargin, 0.002f);
  EXPECT_FALSE(w.train.toJson().contains("anchor_margin_mm"));
  const BakeConfig m =
      parseBakeConfig({{"output", "out"}, {"train", {{"anchor_margin_mm", 6}}}}, "recipe.json", "/base");
  EXPECT_FLOAT_EQ(m.train.anchorMargin, 0.006f);
  EXPECT_EQ(m.train.toJson()["anchor_margin_mm"].get<double>(), 6.0);  // as written, not 6.000000052
  EXPECT_NE(
      errorOf({{"output", "o"}, {"train", {{"anchor_margin_mm", 60}}}}).find("train.anchor_margin_mm: 60 is outside"),
      std::string::npos);
  // The third anchor set (cover anchors): off unless the recipe asks, and then recorded.
  EXPECT_FALSE(w.train.coverAnchors);
  EXPECT_FALSE(w.train.toJson().contains("cover_anchors"));
  const BakeConfig c3 =
      parseBakeConfig({{"output", "out"}, {"train", {{"cover_anchors", true}}}}, "recipe.json", "/base");
  EXPECT_TRUE(c3.train.coverAnchors);
  EXPECT_EQ(c3.train.toJson()["cover_anchors"], true);
  // The gravity values in Theta: off unless asked for (and then recorded; absent by default, so that the
  // fingerprints of earlier bakes stay).
  EXPECT_FALSE(w.train.rootGravity);
  EXPECT_FALSE(w.train.toJson().contains("root_gravity"));
  const BakeConfig g =
      parseBakeConfig({{"output", "out"}, {"train", {{"root_gravity", true}}}}, "recipe.json", "/base");
  EXPECT_TRUE(g.train.rootGravity);
  EXPECT_EQ(g.train.toJson()["root_gravity"], true);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"root_gravity", "yes"}}}}).find("train.root_gravity"),
            std::string::npos);
  // Distillation: off unless asked for (absent from the fingerprint), its settings recorded when on.
  EXPECT_EQ(w.train.distill.poses, 0u);
  EXPECT_FALSE(w.train.toJson().contains("distill"));
  const BakeConfig d = parseBakeConfig(
      {{"output", "out"}, {"train", {{"distill", {{"poses", 3000}, {"mix_share", 0.25}, {"neighbours", 4}}}}}},
      "recipe.json", "/base");
  EXPECT_EQ(d.train.distill.poses, 3000u);
  EXPECT_DOUBLE_EQ(d.train.distill.mixShare, 0.25);
  EXPECT_EQ(d.train.distill.neighbours, 4);
  EXPECT_DOUBLE_EQ(d.train.distill.swapProbability, DistillSettings{}.swapProbability);
  EXPECT_EQ(d.train.toJson()["distill"]["poses"], 3000);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"distill", {{"mix_share", 0.5}}}}}})
                .find("train.distill.poses: is "
                      "required"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"distill", {{"poses", 10}, {"share", 0.5}}}}}})
                .find("train.distill.share: unknown key"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"distill", {{"poses", 10}, {"mix_share", 2}}}}}})
                .find("train.distill.mix_share: 2 is outside"),
            std::string::npos);
}

TEST(BakeConfig, ErrorsNameTheKey) {
  EXPECT_NE(errorOf({{"output", "o"}, {"colour", 1}}).find("colour: unknown key"), std::string::npos);
  EXPECT_NE(
      errorOf({{"output", "o"}, {"train", {{"codebook_size", 70000}}}}).find("train.codebook_size: 70000 is outside"),
      std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"hidden_layerz", 3}}}}).find("train.hidden_layerz: unknown key"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"max_epochs", 1.5}}}}).find("train.max_epochs: must be an integer"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"activation", "relu"}}}}).find("train.activation"),
            std::string::npos);
  EXPECT_NE(
      errorOf({{"output", "o"}, {"train", {{"learning_rate", "fast"}}}}).find("train.learning_rate: must be a number"),
      std::string::npos);
  EXPECT_NE(
      errorOf({{"output", "o"}, {"train", {{"normal_code_weight", 0}}}}).find("train.normal_code_weight: 0 is outside"),
      std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"mesh_weight_floor", 1.5}}}})
                .find("train.mesh_weight_floor: 1.5 is outside"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"anchor_calibration", "some"}}}})
                .find("train.anchor_calibration: must be \"strict\" or \"none\""),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"input_joints", "Spine"}}}})
                .find("train.input_joints: must be a non-empty array"),
            std::string::npos);
  EXPECT_NE(errorOf({{"name", "../x"}, {"output", "o"}}).find("name"), std::string::npos);
  EXPECT_NE(errorOf({{"name", "x"}}).find("output: is required"), std::string::npos);
  EXPECT_NE(errorOf(nlohmann::json::array()).find("must be a JSON object"), std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"part1", 3}}).find("part1: must be a JSON object"), std::string::npos);
}

namespace {
// A part 1 section whose clip exists (this very source file stands in: the config only checks that
// files exist; reading them is part 1's work).
nlohmann::json part1(nlohmann::json extra = nlohmann::json::object()) {
  nlohmann::json p = {{"clips", {kThisFile}}, {"thinning", {{"target_poses", 200}}}};
  for (auto it = extra.begin(); it != extra.end(); ++it) p[it.key()] = it.value();
  return p;
}
std::string part1Error(nlohmann::json extra) { return errorOf({{"output", "o"}, {"part1", part1(std::move(extra))}}); }
bool says(const std::string& error, const std::string& what) {
  if (error.find(what) != std::string::npos) return true;
  ADD_FAILURE() << "error '" << error << "' does not say '" << what << "'";
  return false;
}
}  // namespace

TEST(BakeConfig, AnchorPosesAsPlayed) {
  // The anchors' poses: the training poses unless the recipe asks for the frames as played (then recorded
  // with their count; absent by default, likewise), which need part1's clips.
  const BakeConfig w = parseBakeConfig({{"output", "o"}, {"part1", part1()}}, "recipe.json", "/base");
  EXPECT_FALSE(w.train.anchorsAsPlayed);
  EXPECT_FALSE(w.train.toJson().contains("anchor_poses"));
  const BakeConfig ap = parseBakeConfig(
      {{"output", "o"}, {"part1", part1()}, {"train", {{"anchor_poses", "as_played"}}}}, "recipe.json", "/base");
  EXPECT_TRUE(ap.train.anchorsAsPlayed);
  EXPECT_EQ(ap.train.anchorFramesAsPlayed, 400u);
  EXPECT_EQ(ap.train.toJson()["anchor_poses"], nlohmann::json({{"from", "as_played"}, {"frames", 400}}));
  const BakeConfig ap2 = parseBakeConfig(
      {{"output", "o"}, {"part1", part1()}, {"train", {{"anchor_poses", {{"from", "as_played"}, {"frames", 50}}}}}},
      "recipe.json", "/base");
  EXPECT_EQ(ap2.train.anchorFramesAsPlayed, 50u);
  EXPECT_FALSE(ap2.train.anchorFramesSimulated);
  EXPECT_FALSE(ap2.simulatesAnchorFrames());
  EXPECT_FALSE(ap2.train.toJson()["anchor_poses"].contains("simulated"));
  const BakeConfig ap3 = parseBakeConfig({{"output", "o"},
                                          {"part1", part1()},
                                          {"train", {{"anchor_poses", {{"from", "as_played"}, {"simulated", true}}}}}},
                                         "recipe.json", "/base");
  EXPECT_TRUE(ap3.simulatesAnchorFrames());
  EXPECT_EQ(ap3.train.toJson()["anchor_poses"]["simulated"], true);
  EXPECT_EQ(ap3.anchorFramesDatasetDir(), std::filesystem::path("/base/o/work/anchor_frames_dataset"));
  EXPECT_NE(errorOf({{"output", "o"},
                     {"part1", part1()},
                     {"train", {{"anchor_poses", {{"from", "training"}, {"simulated", true}}}}}})
                .find("train.anchor_poses.simulated: simulates frames as played"),
            std::string::npos);
  EXPECT_FALSE(parseBakeConfig({{"output", "o"}, {"train", {{"anchor_poses", "training"}}}}, "recipe.json", "/base")
                   .train.toJson()
                   .contains("anchor_poses"));
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"anchor_poses", "as_played"}}}}).find("has no part1 section"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"part1", part1()}, {"train", {{"anchor_poses", "played"}}}})
                .find("train.anchor_poses: must be \"training\" or \"as_played\""),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"part1", part1()}, {"train", {{"anchor_poses", {{"frames", 5}}}}}})
                .find("train.anchor_poses.from: is required"),
            std::string::npos);
}

TEST(BakeConfig, Part1DefaultsAndValues) {
  const BakeConfig d = parseBakeConfig({{"output", "o"}, {"part1", part1()}}, "recipe.json", "/base");
  ASSERT_TRUE(d.part1.has_value());
  EXPECT_TRUE(d.part1->characterFile.empty());  // the embedded default character
  EXPECT_TRUE(d.part1->characterRecipe.empty());
  EXPECT_EQ(d.part1->clips.size(), 1u);
  EXPECT_EQ(d.part1->targetPoses, 200u);
  EXPECT_EQ(d.part1->thinningTolerance, 0.f);
  EXPECT_EQ(d.part1->growFrom, 0u);
  EXPECT_TRUE(d.part1->includeRestPose);
  EXPECT_EQ(d.part1->inputJoints, defaultInputJointNames());
  EXPECT_EQ(d.part1->simulation.material.name, "jersey");
  EXPECT_EQ(d.part1->transfer.normalMap.width, 360u);

  const BakeConfig c = parseBakeConfig(
      {{"output", "o"},
       {"work", "/tmp/w"},
       {"part1", part1({{"character", {{"file", kThisFile}, {"garment_mesh", {"shirt"}}}},
                        {"clips", {{{"file", kThisFile}, {"naming", "mixamo"}, {"joint_map", {{"Hips", "Hips"}}}}}},
                        {"input_joints", {"Spine", "Spine1"}},
                        {"thinning", {{"tolerance", 0.25}, {"include_rest_pose", false}}},
                        {"simulation",
                         {{"preset", "stiff"},
                          {"vertices", 4000},
                          {"threads", 2},
                          {"substeps", 4},
                          {"gravity", 0},
                          {"attach_band", 0.03},
                          {"damping", 1.5},
                          {"limb_garment_reach", 0.1},
                          {"limb_neck_range", 45},
                          {"limb_one_surface", false},
                          {"limb_turn_search", false},
                          {"static_solve", true},
                          {"static_tolerance", 0.002},
                          {"static_iterations", 25},
                          {"equilibrium_substeps", 60},
                          {"carry", "translation"},
                          {"retry_carries", {"translation"}},
                          {"safer_path_retries", false}}},
                        {"transfer",
                         {{"smoothing_strength", 0.3},
                          {"smoothing_weights", "uniform"},
                          {"cover_body_mm", 5},
                          {"cover_recorded_pose", false}}},
                        {"normal_maps", {{"size", 128}, {"bit_depth", 8}}}})}},
      "recipe.json", "/base");
  EXPECT_EQ(c.work, std::filesystem::path("/tmp/w"));  // absolute paths stay as they are
  EXPECT_EQ(c.dataset, std::filesystem::path("/tmp/w/dataset"));
  const DatasetBuildSettings& s = *c.part1;
  EXPECT_EQ(s.characterFile, std::filesystem::path(kThisFile));
  EXPECT_EQ(s.garmentMeshNames, std::vector<std::string>{"shirt"});
  EXPECT_EQ(s.clips[0].naming, io::JointNaming::Mixamo);
  ASSERT_EQ(s.clips[0].jointMap.size(), 1u);
  EXPECT_EQ(s.inputJoints.size(), 2u);
  EXPECT_FLOAT_EQ(s.thinningTolerance, 0.25f);
  EXPECT_EQ(s.targetPoses, 0u);
  EXPECT_FALSE(s.includeRestPose);
  EXPECT_EQ(s.simulation.material.name, "stiff");
  EXPECT_EQ(s.simulationVertices, 4000u);
  EXPECT_EQ(s.threads, 2);
  EXPECT_EQ(s.simulation.substeps, 4);
  EXPECT_FLOAT_EQ(s.simulation.attachTopFraction, 0.03f);
  EXPECT_FLOAT_EQ(s.simulation.material.damping, 1.5f);
  EXPECT_FLOAT_EQ(s.limbClearance.garmentReach, 0.1f);
  EXPECT_FLOAT_EQ(d.part1->limbClearance.garmentReach, LimbClearanceSettings{}.garmentReach);
  EXPECT_FLOAT_EQ(s.limbClearance.neckRangeDegrees, 45.f);
  EXPECT_FLOAT_EQ(d.part1->limbClearance.neckRangeDegrees, 90.f);
  // One-surface bodies' limbs: on by default, recorded, and off in settings recorded before the key (their
  // truth is simulated as it was baked).
  EXPECT_FALSE(s.limbClearance.oneSurfaceLimbs);
  EXPECT_TRUE(d.part1->limbClearance.oneSurfaceLimbs);
  EXPECT_EQ(d.part1->toJson()["simulation"]["limb_one_surface"], true);
  EXPECT_TRUE(poseShapeSettingsFromJson(d.part1->toJson(), "dataset settings").limbClearance.oneSurfaceLimbs);
  nlohmann::json beforeOneSurface = d.part1->toJson();
  beforeOneSurface["simulation"].erase("limb_one_surface");
  EXPECT_FALSE(poseShapeSettingsFromJson(beforeOneSurface, "dataset settings").limbClearance.oneSurfaceLimbs);
  // The turn search likewise.
  EXPECT_FALSE(s.limbClearance.turnSearch);
  EXPECT_TRUE(d.part1->limbClearance.turnSearch);
  EXPECT_EQ(d.part1->toJson()["simulation"]["limb_turn_search"], true);
  EXPECT_TRUE(poseShapeSettingsFromJson(d.part1->toJson(), "dataset settings").limbClearance.turnSearch);
  nlohmann::json beforeTurnSearch = d.part1->toJson();
  beforeTurnSearch["simulation"].erase("limb_turn_search");
  EXPECT_FALSE(poseShapeSettingsFromJson(beforeTurnSearch, "dataset settings").limbClearance.turnSearch);
  EXPECT_FLOAT_EQ(d.part1->simulation.material.damping, clothMaterialPreset("jersey").damping);
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(s.toJson(), "dataset settings").simulation.material.damping, 1.5f);
  EXPECT_FALSE(d.part1->toJson()["simulation"].contains("damping"));  // the preset's: not recorded
  EXPECT_TRUE(s.simulation.staticSolve);
  EXPECT_FLOAT_EQ(s.simulation.staticTolerance, 0.002f);
  EXPECT_EQ(s.simulation.staticIterations, 25);
  EXPECT_FALSE(d.part1->simulation.staticSolve);  // off unless asked for
  // Recorded in the dataset settings only when on, so that other bakes' datasets stay as they were.
  EXPECT_EQ(s.toJson()["simulation"]["static_iterations"], 25);
  EXPECT_FALSE(d.part1->toJson()["simulation"].contains("static_solve"));
  // ...and read back from them (the replay's truth simulates as the bake did).
  const PoseShapeSettings back = poseShapeSettingsFromJson(s.toJson(), "dataset settings");
  EXPECT_TRUE(back.simulation.staticSolve);
  EXPECT_EQ(back.simulation.staticIterations, 25);
  // The end phase's own substeps likewise: recorded only when set, read back.
  EXPECT_EQ(s.simulation.equilibriumSubsteps, 60);
  EXPECT_EQ(d.part1->simulation.equilibriumSubsteps, 0);
  EXPECT_EQ(s.toJson()["simulation"]["equilibrium_substeps"], 60);
  EXPECT_FALSE(d.part1->toJson()["simulation"].contains("equilibrium_substeps"));
  EXPECT_EQ(back.simulation.equilibriumSubsteps, 60);
  // The carry: recorded only when not the skinning one, read back; settings without it (a model
  // baked before it was a setting) carry by skinning.
  EXPECT_EQ(s.simulation.carry, ClothCarry::Translation);
  EXPECT_EQ(d.part1->simulation.carry, ClothCarry::Skinning);
  EXPECT_EQ(back.simulation.carry, ClothCarry::Translation);
  EXPECT_FALSE(d.part1->toJson()["simulation"].contains("carry"));
  nlohmann::json withoutCarry = s.toJson();
  withoutCarry["simulation"].erase("carry");
  EXPECT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").simulation.carry, ClothCarry::Skinning);
  // The retries' carries: the skinning one then the translation one unless the recipe says otherwise;
  // recorded unless the skinning one alone, and settings without them (a model baked before) retry by
  // the skinning carry alone.
  const std::vector<ClothCarry> both = {ClothCarry::Skinning, ClothCarry::Translation};
  EXPECT_EQ(s.simulation.retryCarries, std::vector<ClothCarry>{ClothCarry::Translation});
  EXPECT_EQ(d.part1->simulation.retryCarries, both);
  EXPECT_EQ(back.simulation.retryCarries, std::vector<ClothCarry>{ClothCarry::Translation});
  EXPECT_EQ(d.part1->toJson()["simulation"]["retry_carries"], nlohmann::json({"skinning", "translation"}));
  withoutCarry["simulation"].erase("retry_carries");
  EXPECT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").simulation.retryCarries,
            std::vector<ClothCarry>{ClothCarry::Skinning});
  // The safer-path retries: on by default, recorded only when on; off when asked, and in settings
  // recorded before them (a model baked before keeps the truth it was baked on).
  EXPECT_FALSE(s.simulation.saferPathRetries);
  EXPECT_FALSE(s.toJson()["simulation"].contains("safer_path_retries"));
  EXPECT_TRUE(d.part1->simulation.saferPathRetries);
  EXPECT_EQ(d.part1->toJson()["simulation"]["safer_path_retries"], true);
  EXPECT_TRUE(poseShapeSettingsFromJson(d.part1->toJson(), "dataset settings").simulation.saferPathRetries);
  EXPECT_FALSE(poseShapeSettingsFromJson(withoutCarry, "dataset settings").simulation.saferPathRetries);
  // The dual-quaternion carry by name, recorded as such.
  nlohmann::json dualCarry = d.part1->toJson();
  dualCarry["simulation"]["carry"] = "dual_quaternion";
  dualCarry["simulation"]["retry_carries"] = {"skinning", "translation", "dual_quaternion"};
  const PoseShapeSettings dual = poseShapeSettingsFromJson(dualCarry, "dataset settings");
  EXPECT_EQ(dual.simulation.carry, ClothCarry::DualQuaternion);
  EXPECT_EQ(dual.simulation.retryCarries.back(), ClothCarry::DualQuaternion);
  // The re-skinning of corrected poses (pose_transfer.hpp): 0.4 by default, recorded; absent: 0.
  EXPECT_FLOAT_EQ(d.part1->transfer.reskinMinSingularValue, 0.4f);
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(d.part1->toJson(), "dataset settings").transfer.reskinMinSingularValue,
                  0.4f);
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").transfer.reskinMinSingularValue, 0.4f);
  withoutCarry["transfer"].erase("reskin_min_singular_value");
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").transfer.reskinMinSingularValue, 0.f);
  // The game mesh kept over the body (body_cover.hpp): 2 mm by default, as the recipe says, recorded and read
  // back; settings without it (a model baked before) stored the game mesh as transferred.
  EXPECT_FLOAT_EQ(d.part1->transfer.cover.margin, 0.002f);
  EXPECT_FLOAT_EQ(s.transfer.cover.margin, 0.005f);
  EXPECT_FLOAT_EQ(back.transfer.cover.margin, 0.005f);
  EXPECT_FALSE(s.transfer.cover.recordedPose);
  EXPECT_FALSE(back.transfer.cover.recordedPose);
  EXPECT_EQ(d.part1->toJson()["transfer"]["cover_body_mm"], 2.f);
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").transfer.cover.margin, 0.005f);
  // And again in the recorded pose (pose_shape.hpp step 4): on by default, recorded; settings from before it
  // was a setting (no key) did not.
  EXPECT_TRUE(d.part1->transfer.cover.recordedPose);
  EXPECT_EQ(d.part1->toJson()["transfer"]["cover_recorded_pose"], true);
  nlohmann::json defaults = d.part1->toJson();
  EXPECT_TRUE(poseShapeSettingsFromJson(defaults, "dataset settings").transfer.cover.recordedPose);
  defaults["transfer"].erase("cover_recorded_pose");
  EXPECT_FALSE(poseShapeSettingsFromJson(defaults, "dataset settings").transfer.cover.recordedPose);
  withoutCarry["transfer"].erase("cover_body_mm");
  EXPECT_FLOAT_EQ(poseShapeSettingsFromJson(withoutCarry, "dataset settings").transfer.cover.margin, 0.f);
  EXPECT_FLOAT_EQ(d.part1->simulation.attachTopFraction, ClothSimSettings{}.attachTopFraction);
  EXPECT_EQ(s.simulation.gravity, Vec3f::Zero());
  EXPECT_FLOAT_EQ(d.part1->simulation.gravity.y(), -9.81f);
  EXPECT_FLOAT_EQ(s.transfer.smoothing.strength, 0.3f);
  EXPECT_EQ(s.transfer.smoothing.weights, LaplacianWeights::Uniform);
  EXPECT_EQ(s.transfer.normalMap.width, 128u);
  EXPECT_EQ(s.transfer.normalMap.height, 128u);
  EXPECT_EQ(s.normalMapBitDepth, 8u);
}

TEST(BakeConfig, Part1ErrorsNameTheKeyBeforeAnyWork) {
  says(part1Error({{"colour", 1}}), "part1.colour: unknown key");
  says(part1Error({{"simulation", {{"subteps", 3}}}}), "part1.simulation.subteps: unknown key");
  says(part1Error({{"simulation", {{"preset", "silk"}}}}), "part1.simulation.preset");
  says(part1Error({{"simulation", {{"substeps", 0}}}}), "part1.simulation.substeps: 0 is outside");
  says(part1Error({{"simulation", {{"attach_band", 0.9}}}}), "part1.simulation.attach_band: 0.9 is outside");
  says(part1Error({{"simulation", {{"limb_garment_reach", -0.1}}}}),
       "part1.simulation.limb_garment_reach: -0.1 is outside");
  says(part1Error({{"simulation", {{"limb_neck_range", 800}}}}), "part1.simulation.limb_neck_range: 800 is outside");
  says(part1Error({{"simulation", {{"limb_one_surface", 1}}}}), "part1.simulation.limb_one_surface");
  says(part1Error({{"simulation", {{"limb_turn_search", 1}}}}), "part1.simulation.limb_turn_search");
  says(part1Error({{"simulation", {{"static_iterations", 0}}}}), "part1.simulation.static_iterations: 0 is outside");
  says(part1Error({{"transfer", {{"cover_body_mm", 30}}}}), "part1.transfer.cover_body_mm: 30 is outside");
  says(part1Error({{"transfer", {{"cover_recorded_pose", 1}}}}),
       "part1.transfer.cover_recorded_pose: must be true or false");
  says(part1Error({{"simulation", {{"carry", "rigid"}}}}),
       "part1.simulation.carry: 'rigid' is not \"skinning\", \"translation\" or \"dual_quaternion\"");
  says(part1Error({{"simulation", {{"retry_carries", "translation"}}}}),
       "part1.simulation.retry_carries: must be a non-empty array of strings");
  says(part1Error({{"simulation", {{"retry_carries", {"skinning", "rigid"}}}}}),
       "part1.simulation.retry_carries[1]: 'rigid' is not \"skinning\", \"translation\" or \"dual_quaternion\"");
  says(part1Error({{"simulation", {{"retry_carries", {"skinning", "skinning"}}}}}),
       "part1.simulation.retry_carries: must name one to three different carries");
  says(part1Error({{"normal_maps", {{"size", 30}}}}), "part1.normal_maps.size: must be a multiple of 4");
  says(part1Error({{"normal_maps", {{"bit_depth", 12}}}}), "part1.normal_maps.bit_depth: must be 8 or 16");
  says(part1Error({{"thinning", {{"tolerance", 0.1}, {"target_poses", 10}}}}), "part1.thinning: give exactly one");
  says(part1Error({{"thinning", nlohmann::json::object()}}), "part1.thinning: give exactly one");
  says(part1Error({{"thinning", {{"target_poses", 1}}}}), "part1.thinning.target_poses: 1 is outside");
  says(part1Error({{"thinning", {{"target_poses", 10}, {"include_rest_pose", 1}}}}),
       "part1.thinning.include_rest_pose");
  says(part1Error({{"thinning", {{"tolerance", 0.1}, {"grow_from", 10}}}}), "part1.thinning.grow_from: needs");
  says(part1Error({{"thinning", {{"target_poses", 10}, {"grow_from", 10}}}}),
       "part1.thinning.grow_from: is 10, not below target_poses (10)");
  says(part1Error({{"thinning", {{"target_poses", 10}, {"grow_from", 1}}}}), "part1.thinning.grow_from: 1 is outside");
  EXPECT_EQ(
      parseBakeConfig({{"output", "o"}, {"part1", part1({{"thinning", {{"target_poses", 40}, {"grow_from", 20}}}})}},
                      "recipe.json", "/base")
          .part1->growFrom,
      20u);
  says(part1Error({{"synthesis", {{"poses", 10}}}}), "part1.synthesis.joints: is required");
  says(part1Error({{"synthesis", {{"joints", {"LeftShoulder"}}}}}), "part1.synthesis.poses: is required");
  says(part1Error({{"synthesis", {{"joints", {"LeftShoulder"}}, {"poses", 10}, {"candidates", 5}}}}),
       "part1.synthesis.candidates: is 5, fewer than the 10 poses");
  says(part1Error({{"synthesis", {{"joints", {"LeftShoulder"}}, {"poses", 10}, {"extend", 2}}}}),
       "part1.synthesis.extend: 2 is outside");
  says(part1Error({{"synthesis", {{"joints", {"LeftShoulder"}}, {"poses", 10}, {"count", 2}}}}), "part1.synthesis");
  {
    const DatasetBuildSettings syn =
        *parseBakeConfig(
             {{"output", "o"},
              {"part1", part1({{"synthesis", {{"joints", {"LeftShoulder", "RightShoulder"}}, {"poses", 300}}}})}},
             "recipe.json", "/base")
             .part1;
    EXPECT_EQ(syn.synthesis.joints, (std::vector<std::string>{"LeftShoulder", "RightShoulder"}));
    EXPECT_EQ(syn.synthesis.poses, 300u);
    EXPECT_EQ(syn.synthesis.candidates, 0u);  // 8 x poses
    EXPECT_FLOAT_EQ(syn.synthesis.extend, 0.25f);
    EXPECT_TRUE(syn.synthesis.enabled());
    EXPECT_FALSE(
        parseBakeConfig({{"output", "o"}, {"part1", part1()}}, "recipe.json", "/base").part1->synthesis.enabled());
  }
  says(part1Error({{"clips", {"/nonexistent/walk.bvh"}}}), "part1.clips[0]: file /nonexistent/walk.bvh does not exist");
  says(part1Error({{"clips", nlohmann::json::array()}}), "part1.clips: must be a non-empty array");
  says(part1Error({{"clips", {{{"file", kThisFile}, {"naming", "cmu"}}}}}), "part1.clips[0].naming");
  says(part1Error({{"character", "mannequin"}}), "part1.character: must be \"default\"");
  says(part1Error({{"character", {{"file", "/nonexistent/c.glb"}}}}), "part1.character.file: file");
  says(part1Error({{"character", {{"recipe", kThisFile}, {"garment_mesh", {"x"}}}}}),
       "mesh names apply to an imported");
  says(part1Error({{"input_joints", {"Spine", 3}}}), "part1.input_joints: must hold non-empty strings");
  says(part1Error({{"transfer", {{"smoothing_weights", "cubic"}}}}), "part1.transfer.smoothing_weights");
  says(errorOf({{"output", "o"}, {"part1", {{"thinning", {{"target_poses", 10}}}}}}), "part1.clips: is required");
  says(errorOf({{"output", "o"}, {"part1", {{"clips", {kThisFile}}}}}), "part1.thinning: is required");
}

TEST(BakeConfig, MissingFileIsAClearError) { EXPECT_THROW(loadBakeConfig("/nonexistent/recipe.json"), Error); }

// The committed default model is what its committed recipe makes: the part 2 settings the model's
// metadata records (and its input joints) are the recipe's. Editing assets/default/bake.json without
// re-baking fails here, not silently at the next `swish bake` (which would re-train).
TEST(BakeConfig, CommittedDefaultModelMatchesItsRecipe) {
  const std::filesystem::path recipe = test::sourceDir() / "assets/default/bake.json";
  BakeConfig cfg;
  try {
    cfg = loadBakeConfig(recipe);
  } catch (const Error& e) {
    // The recipe names the Debian CMU clips, which must exist for it to load.
    GTEST_SKIP() << "the default recipe does not load here (" << e.what() << "); assimp-testmodels missing?";
  }
  const Model m = loadModel(cfg.modelPath());
  const nlohmann::json meta = nlohmann::json::parse(m.metadata);
  EXPECT_EQ(meta.at("settings"), cfg.train.toJson());
  std::vector<std::string> names;
  for (uint32_t j : m.inputJoints) names.push_back(m.skeleton.joints.at(j).name);
  EXPECT_EQ(names, cfg.train.inputJoints.empty() ? cfg.part1->inputJoints : cfg.train.inputJoints);
  EXPECT_EQ(m.mlp.inputSize(), 6 * int(names.size()));
}
