// The whole bake, `swish bake CONFIG` as runBake runs it: the embedded default character, real CMU
// mocap (Debian's assimp-testmodels clip 01_01.bvh), tens of thinned poses, the source cloth simulation
// on the welded game mesh (no subdivision, short transition), transfer + smoothing + 16x16 normal maps,
// then part 2 with a small network. The model it writes must load and run through the runtime's MLP
// and reference frame (and on the GPU path when a Vulkan device is there), and a re-run must redo
// nothing. Sized to run in well under a minute on two cores.
//
// The default character simulates since the limb clearance (bake/poses/limb_clearance.hpp) turns hanging
// arms out of the mannequin's torso and the solver's top band stays on the trunk; before that every
// pose failed and these tests were disabled.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "support/error_message.hpp"
#include "support/gpu_test.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/core/error.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

const fs::path kClip = test::debianMocap("01_01.bvh");

nlohmann::json smallConfig() {
  return {{"name", "whole"},
          {"output", "out"},
          {"part1",
           {{"character", "default"},
            {"clips", {kClip.string()}},
            {"thinning", {{"target_poses", 30}}},
            {"simulation",
             {{"vertices", 0},
              {"transition_seconds", 0.3},
              {"settle_seconds", 0.2},
              {"frame_rate", 20},
              {"threads", 2},
              {"gravity", 0},
              {"equilibrium_seconds", 0.1},
              {"check_poses", 2}}},
            {"normal_maps", {{"size", 16}, {"dilation_rings", 2}}},
            {"preview", {{"poses", 2}, {"size", 96}}}}},
          {"train",
           {{"mesh_components", 8},
            {"normal_code_dims", 4},
            {"database_size", 8},
            {"codebook_size", 32},
            {"hidden_layers", 2},
            {"hidden_width", 16},
            {"max_epochs", 150},
            {"patience", 40},
            {"test_fraction", 0.15},
            {"bc5_baseline", false}}}};
}

// One bake shared by the tests below (it is the expensive part).
struct WholeBake {
  test::TempDir tmp{"bake_whole"};  // removed when the process ends
  fs::path dir;
  BakeConfig config;
  BakeRunResult first;
  std::vector<std::string> lines;
};

WholeBake& sharedBake() {
  static std::unique_ptr<WholeBake> b = [] {
    auto w = std::make_unique<WholeBake>();
    w->dir = w->tmp / "bake";  // not there yet: runBake makes what it needs
    w->config = parseBakeConfig(smallConfig(), "whole.json", w->dir);
    BakeRunOptions o;
    o.log = [raw = w.get()](const std::string& l) { raw->lines.push_back(l); };
    w->first = runBake(w->config, o);
    return w;
  }();
  return *b;
}

bool requireClip() { return fs::exists(kClip); }

}  // namespace

// `swish bake --check-simulation N` (checkSimulation): a seeded sample of the thinned poses simulated and
// measured without a dataset; limb clearance runs on the sample alone (a check of 24 corpus poses spent
// 131 s of its 163 s clearing the other 4050 before), and the sample's figures are those of the full plan.
TEST(BakeWhole, TheSimulationCheckClearsAndSimulatesItsSampleOnly) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  const test::TempDir tmp("bake_check");
  const BakeConfig cfg = parseBakeConfig(smallConfig(), "whole.json", tmp.path());
  DatasetBuildSettings s = *cfg.part1;
  s.quality.poses = 1;
  std::vector<std::string> lines;
  const nlohmann::json r = checkSimulation(s, 3, 1, [&](const std::string& l) { lines.push_back(l); });
  const nlohmann::json& sim = r.at("simulation");
  EXPECT_EQ(sim.at("poses").get<size_t>(), 3u);
  EXPECT_GT(sim.at("seconds_per_pose_per_core").get<double>(), 0.0);
  const bool clearedThree = std::any_of(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find(" of 3 poses had a limb in the trunk") != std::string::npos;
  });
  EXPECT_TRUE(clearedThree) << "the clearance line names the 3 sampled poses";
  // The same sample and figures as with every pose cleared first (a pose's clearance is its own).
  const DatasetPosePlan all = planDatasetPoses(s, {});
  const DatasetPosePlan some = planDatasetPoses(s, {}, [](size_t n) {
    return std::vector<uint32_t>{0, uint32_t(n - 1)};
  });
  ASSERT_EQ(all.toSimulate.size(), some.toSimulate.size());
  for (size_t i : {size_t(0), all.toSimulate.size() - 1})
    for (size_t j = 0; j < all.toSimulate[i].local.size(); ++j)
      EXPECT_EQ(all.toSimulate[i].local[j].coeffs(), some.toSimulate[i].local[j].coeffs()) << "pose " << i;
  EXPECT_EQ(some.toSimulate[1].local.size(), some.recorded[1].local.size());
  for (size_t j = 0; j < some.recorded[1].local.size(); ++j)
    EXPECT_EQ(some.toSimulate[1].local[j].coeffs(), some.recorded[1].local[j].coeffs()) << "pose 1 is not cleared";
  EXPECT_THROW(planDatasetPoses(s, {}, [](size_t n) { return std::vector<uint32_t>{uint32_t(n)}; }), Error);
}

TEST(BakeWhole, DefaultCharacterAndMocapToLoadableModel) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  WholeBake& w = sharedBake();
  const nlohmann::json& p1 = w.first.part1;
  ASSERT_TRUE(p1.is_object());
  EXPECT_GT(p1["samples"].get<size_t>(), 1000u);  // 01_01.bvh has ~2750 frames
  const size_t kept = p1["kept_poses"].get<size_t>();
  EXPECT_NEAR(double(kept), 30.0, 3.0);
  const size_t inDataset = p1["transferred"].get<size_t>();
  EXPECT_EQ(inDataset + p1["failed"].size(), kept);  // every pose is either in the dataset or reported
  EXPECT_GE(inDataset, kept * 3 / 4);
  EXPECT_TRUE(fs::exists(w.config.reportDir() / "part1.json"));
  EXPECT_TRUE(fs::exists(w.config.reportDir() / "report.md"));
  // The simulation's own figures (issue 18): failures per reason, retries, CPU seconds per pose,
  // equilibrium residuals, and convergence and noise on the 2 sampled poses.
  const nlohmann::json& sim = p1["simulation"];
  ASSERT_TRUE(sim.is_object()) << p1.dump();
  EXPECT_EQ(sim["poses"].get<size_t>(), kept);
  EXPECT_TRUE(sim["failures_by_reason"].is_object());
  EXPECT_TRUE(sim["retried"].is_array());
  EXPECT_GT(sim["seconds_per_pose_per_core"].get<double>(), 0.0);
  EXPECT_GE(sim["equilibrium_residual_mean"].get<double>(), 0.0);
  const nlohmann::json& q = sim["quality"];
  ASSERT_TRUE(q.is_object()) << sim.dump();
  // Every sampled pose has its reference solve, or the failure is listed.
  EXPECT_LE(q["convergence_poses"].get<size_t>(), 2u);
  EXPECT_GE(q["convergence_poses"].get<size_t>() + q["reference_failures"].size(), 2u);
  if (q["convergence_poses"].get<size_t>() > 0) {
    EXPECT_GT(q["convergence_mean_mm"].get<double>(), 0.0);  // twice the substeps moves something
    EXPECT_GT(q["convergence_p95_mm"].get<double>(), 0.0);
  }
  EXPECT_GE(q["noise_mean_mm"].get<double>(), 0.0);
  // What of the convergence figure the path explains, and the stretch at both settings.
  EXPECT_GE(q["path_sensitivity_poses"].get<size_t>() + q["reference_failures"].size(), 2u);
  EXPECT_GE(q["path_sensitivity_mean_mm"].get<double>(), 0.0);
  if (q["convergence_poses"].get<size_t>() > 0) {
    EXPECT_TRUE(std::isfinite(q["edge_strain_mean_percent"].get<double>()));
    EXPECT_NE(q["edge_strain_mean_percent"].get<double>(), q["reference_edge_strain_mean_percent"].get<double>());
  }
  EXPECT_TRUE(fs::exists(w.config.previewDir() / "preview.json"));
  // The cover (transfer/body_cover.hpp), in the simulated pose and again in the recorded one: the second
  // runs only on poses that limb clearance changed, and the walk's hanging arms are turned out in most.
  const nlohmann::json &cover = p1["body_cover"], &coverRecorded = p1["body_cover_recorded_pose"];
  ASSERT_TRUE(cover.is_object() && coverRecorded.is_object()) << p1.dump();
  EXPECT_LE(cover["poses"].get<size_t>(), inDataset);
  EXPECT_LE(coverRecorded["poses"].get<size_t>(), p1["poses_corrected"].get<size_t>());
  EXPECT_LE(coverRecorded["largest_shift_mm"].get<double>(), 30.0 + 1e-3);  // BodyCoverSettings::maxShift
  std::printf("cover: %zu poses; again in the recorded pose: %zu of the %zu corrected\n", cover["poses"].get<size_t>(),
              coverRecorded["poses"].get<size_t>(), p1["poses_corrected"].get<size_t>());

  // Progress lines with the time left for the long steps.
  bool simLeft = false, transferLeft = false;
  for (const auto& l : w.lines) {
    simLeft |= l.find("simulation") != std::string::npos && l.find("left") != std::string::npos;
    transferLeft |= l.find("transfer") != std::string::npos && l.find("left") != std::string::npos;
  }
  EXPECT_TRUE(simLeft);
  EXPECT_TRUE(transferLeft);

  // The dataset holds exactly the poses that did not fail, with their residuals.
  const Dataset ds = readDataset(w.config.dataset);
  EXPECT_EQ(ds.poses.size(), inDataset);
  EXPECT_EQ(ds.poses.front().normalMap.width, 16u);
  for (const auto& f : p1["failed"])
    for (const auto& pose : ds.poses) EXPECT_NE(pose.id, f["pose"].get<uint32_t>());

  // The model loads and runs: MLP -> PCA -> skinning through the runtime's reference frame. The error
  // of a dataset pose through this path must be what a person would accept of a tiny network (cm, not
  // metres) and finite everywhere.
  const Model model = loadModel(w.first.model);
  EXPECT_EQ(model.gameMesh.vertexCount(), ds.character.garment.vertexCount());
  EXPECT_EQ(model.normalMaps.width, 16u);
  const runtime::MlpEvaluator mlp(model);
  const DatasetPose& pose = ds.poses[ds.poses.size() / 2];
  const auto theta = runtime::computeTheta(model.inputJoints, pose.pose.local);
  std::vector<float> lambda(size_t(mlp.outputSize()));
  mlp.evaluate(theta, lambda);
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.meshWeights.assign(lambda.begin(), lambda.begin() + model.meshComponents());
  in.skinMatrices = model.skeleton.skinningMatrices(pose.pose);
  in.selectedMaps = {0};
  in.blendAlpha = {1.f};
  const auto frame = runtime::referenceFrame(model, in);
  ASSERT_EQ(frame.positions.size(), 1u);
  double meanMm = 0.0;
  for (Eigen::Index v = 0; v < frame.positions[0].rows(); ++v) {
    ASSERT_TRUE(frame.positions[0].row(v).allFinite());
    meanMm += 1000.0 * (frame.positions[0].row(v) - pose.gameMeshWorld.row(v)).norm();
  }
  meanMm /= double(frame.positions[0].rows());
  EXPECT_LT(meanMm, 30.0);
  const auto report = nlohmann::json::parse(std::ifstream(w.config.reportDir() / "report.json"));
  EXPECT_LT(report["vertex_error_held_out"]["total"]["mean_mm"].get<double>(), 30.0);

  // The A-pose joins the walk's poses (no walking frame is near it) as the last pose, simulates (it is
  // where every transition starts) and is always trained on, never held out.
  EXPECT_TRUE(p1["rest_pose_added"].get<bool>());
  const DatasetPose& rest = ds.poses.back();
  EXPECT_EQ(rest.id, kept - 1);
  const Pose restPose = ds.character.skeleton.restPose();
  for (size_t j = 1; j < restPose.local.size(); ++j)  // the root is canonical anyway
    EXPECT_TRUE(rest.pose.local[j].isApprox(restPose.local[j], 1e-6f)) << "joint " << j;
  EXPECT_EQ(report["poses"]["always_trained"], nlohmann::json::array({rest.id}));
}

TEST(BakeWhole, ReRunRedoesNothing) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  WholeBake& w = sharedBake();
  const auto stamp = fs::last_write_time(w.first.model);
  const BakeRunResult again = runBake(w.config);
  EXPECT_EQ(again.part1["simulated"].get<size_t>(), 0u);
  EXPECT_EQ(again.part1["transferred"].get<size_t>(), 0u);
  // Every pose's simulation file is reused, a failed one too (its failure is recorded in it and
  // reported again, not re-simulated).
  EXPECT_EQ(again.part1["simulations_reused"].get<size_t>(), w.first.part1["kept_poses"].get<size_t>());
  EXPECT_EQ(again.part1["failed"], w.first.part1["failed"]);
  EXPECT_TRUE(again.part2Skipped);
  EXPECT_EQ(fs::last_write_time(w.first.model), stamp);
}

// train.anchor_poses {"from": "as_played", "simulated": true}: part 1 simulates frames of the training
// clips as a game plays them into a dataset of their own (beside the shared bake's training poses, whose
// simulations it reuses through the same work folder), part 2 fits the slide and cover anchors on them and
// says so, and a re-run simulates nothing again and keeps the model.
TEST(BakeWhole, AnchorsOnSimulatedFramesAsPlayedAreMadeByPart1AndResumed) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  WholeBake& w = sharedBake();
  nlohmann::json j = smallConfig();
  j["name"] = "played";
  j["output"] = "played";
  j["work"] = w.config.work.string();
  j["train"]["cover_anchors"] = true;
  j["train"]["anchor_poses"] = {{"from", "as_played"}, {"frames", 12}, {"simulated", true}};
  const BakeConfig cfg = parseBakeConfig(j, "played.json", w.dir);
  ASSERT_TRUE(cfg.simulatesAnchorFrames());
  const BakeRunResult first = runBake(cfg);
  EXPECT_EQ(first.part1["simulations_reused"], w.first.part1["kept_poses"]);  // the training poses: reused
  ASSERT_TRUE(first.part1.contains("anchor_frames"));
  EXPECT_EQ(first.part1["anchor_frames"]["kept_poses"].get<size_t>(), 12u);
  EXPECT_EQ(first.part1["anchor_frames"]["simulated"].get<size_t>(), 12u);
  const Dataset frames = readDataset(cfg.anchorFramesDatasetDir());
  ASSERT_GT(frames.poses.size(), 6u);
  const Model m = loadModel(first.model);
  const auto meta = nlohmann::json::parse(m.metadata);
  EXPECT_EQ(meta["body_anchors"]["poses_from"], "as_played");
  EXPECT_EQ(meta["body_anchors"]["as_played"]["simulated"], true);
  EXPECT_EQ(meta["body_anchors"]["as_played"]["frames"].get<size_t>(), frames.poses.size());
  EXPECT_EQ(meta["body_anchors"]["slide_poses"].get<size_t>(), frames.poses.size());
  EXPECT_EQ(meta["settings"]["anchor_poses"]["simulated"], true);
  EXPECT_GT(m.bodyAnchors.anchored(), 0u);
  // Resumed: nothing simulated again, and the model is current.
  const BakeRunResult again = runBake(cfg);
  EXPECT_EQ(again.part1["anchor_frames"]["simulated"].get<size_t>(), 0u);
  EXPECT_EQ(again.part1["anchor_frames"]["simulations_reused"].get<size_t>(), 12u);
  EXPECT_TRUE(again.part2Skipped);
}

// train.input_joints is part 2's, but a joint the character lacks stops the bake before part 1
// simulates anything: the error names the key and the joint, and no simulation file is written.
TEST(BakeWhole, AnUnknownNetworkJointStopsTheBakeBeforeAnySimulation) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  const test::TempDir tmp("bake_whole_joints");
  nlohmann::json j = smallConfig();
  j["train"]["input_joints"] = {"Spine", "LeftForeArm", "LeftTentacle"};
  const BakeConfig cfg = parseBakeConfig(j, "whole.json", tmp / "bake");
  const std::string error = test::errorOf([&] { runBake(cfg); });
  EXPECT_NE(error.find("train.input_joints: joint 'LeftTentacle' is not in character"), std::string::npos) << error;
  EXPECT_TRUE(!fs::exists(cfg.simulationDir()) || fs::is_empty(cfg.simulationDir()));
  EXPECT_FALSE(fs::exists(cfg.modelPath()));
}

// The baked model on the GPU path (gpu::FrameRecorder) against the CPU reference frame.
class BakeWholeGpu : public test::GpuTest {};

TEST_F(BakeWholeGpu, BakedModelRunsOnTheGpuLikeTheReference) {
  if (!requireClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  WholeBake& w = sharedBake();
  const Model model = loadModel(w.first.model);
  const Dataset ds = readDataset(w.config.dataset);
  const runtime::MlpEvaluator mlp(model);
  const uint32_t instances = 2;
  runtime::FrameKernelInputs in;
  in.instanceCount = instances;
  for (uint32_t c = 0; c < instances; ++c) {
    const Pose& pose = ds.poses[c * (ds.poses.size() - 1)].pose;
    std::vector<float> lambda(size_t(mlp.outputSize()));
    mlp.evaluate(runtime::computeTheta(model.inputJoints, pose.local), lambda);
    in.meshWeights.insert(in.meshWeights.end(), lambda.begin(), lambda.begin() + model.meshComponents());
    const auto mats = model.skeleton.skinningMatrices(pose);
    in.skinMatrices.insert(in.skinMatrices.end(), mats.begin(), mats.end());
    in.selectedMaps.push_back(c % model.normalMaps.mapCount());
    in.blendAlpha.push_back(1.f);
  }
  gpu::GpuModel gm(ctx(), model, "baked model");
  gpu::FrameRecorder rec(ctx(), gm, instances, {1, true, true});
  ctx().submitAndWait([&](VkCommandBuffer cmd) { rec.record(cmd, 0, in); });
  const auto gpuOut = rec.download(0);
  const auto ref = runtime::referenceFrame(model, in);
  ASSERT_EQ(gpuOut.positions.size(), ref.positions.size());
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    // Float32 PCA + skinning in a different summation order: well under a micrometre at metre scale.
    EXPECT_LT((gpuOut.positions[i] - ref.positions[i]).cwiseAbs().maxCoeff(), 1e-5f) << "instance " << i;
    EXPECT_LT((gpuOut.normals[i] - ref.normals[i]).cwiseAbs().maxCoeff(), 1e-3f) << "instance " << i;
  }
  ASSERT_EQ(gpuOut.normalMaps.size(), ref.normalMaps.size());
  for (size_t i = 0; i < ref.normalMaps.size(); ++i)
    for (size_t t = 0; t < ref.normalMaps[i].xy.size(); ++t)
      ASSERT_LE(std::abs(int(gpuOut.normalMaps[i].xy[t]) - int(ref.normalMaps[i].xy[t])), 2) << "map " << i;
}
