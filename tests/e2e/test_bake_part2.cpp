// Part 2 of the bake end to end on a synthetic dataset whose truth is known: shapes from a low-rank
// smooth function of the pose, normal maps from pose-dependent sinusoids. trainBake -> report files ->
// saveModel -> loadModel -> the runtime's MLP evaluator and reference frame run on the loaded model.
// The second test drives runBake (what `swish bake CONFIG` runs) on the same dataset written to a
// dataset folder, and checks that a re-run skips part 2. (Part 1 is not wired into runBake yet.)
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/bake/pipeline/part2_training.hpp"
#include "swish/bake/report/bake_report.hpp"
#include "swish/bake/report/subject_evaluation.hpp"
#include "swish/bake/training/body_anchor_fit.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
// `lean`: four joints (the root first), the first (largest) field driven by the root's lean (the gravity
// direction in its frame) instead of a joint, the other two by joints 1 and 2.
Dataset syntheticDataset(uint64_t seed, int poses, uint32_t mapSize, bool lean = false) {
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 120;
  spec.inputJoints = lean ? 4 : 3;
  const Model base = test::makeRandomModel(rng, spec);
  Dataset ds;
  ds.character.name = "synthetic";
  ds.character.skeleton = base.skeleton;
  ds.character.garment = base.gameMesh;
  ds.character.body = base.gameMesh;
  ds.inputJoints = base.inputJoints;
  ds.settings = {{"synthetic", true}, {"seed", seed}};
  const size_t n = base.gameMesh.vertexCount();
  // Three smooth displacement fields (a few mm to 2 cm), driven by smooth functions of Theta.
  MatXf fields(3 * n, 3);
  for (Eigen::Index c = 0; c < 3; ++c)
    for (size_t v = 0; v < n; ++v)
      for (int a = 0; a < 3; ++a)
        fields(Eigen::Index(3 * v + a), c) = 0.02f / float(c + 1) * std::sin(float(v) * 0.1f * float(c + 1) + float(a));
  for (int i = 0; i < poses; ++i) {
    DatasetPose p;
    p.id = uint32_t(i);
    p.pose = test::makeRandomPose(rng, ds.character.skeleton, 0.5f);
    const std::vector<float> th = runtime::computeTheta(ds.inputJoints, true, p.pose.local);
    const size_t g = 6 * ds.inputJoints.size();  // the gravity values
    const Eigen::Vector3f drive =
        lean ? Eigen::Vector3f(2.f * (th[g + 2] + th[g]), std::sin(2.f * th[7]), th[10] * th[13])
             : Eigen::Vector3f(std::sin(2.f * th[1]), th[4] * th[7], std::cos(3.f * th[13]));
    VecXf pre = Eigen::Map<const VecXf>(base.gameMesh.positions.data(), Eigen::Index(3 * n)) + fields * drive;
    p.gameMeshPreSkin = Eigen::Map<const Points3f>(pre.data(), Eigen::Index(n), 3);
    p.gameMeshWorld =
        skinPositions(p.gameMeshPreSkin, base.gameMesh.skin, ds.character.skeleton.skinningMatrices(p.pose));
    p.normalMap = {mapSize, mapSize, std::vector<float>(size_t(mapSize) * mapSize * 2)};
    for (uint32_t y = 0; y < mapSize; ++y)
      for (uint32_t x = 0; x < mapSize; ++x) {
        const float u = (x + .5f) / float(mapSize), v = (y + .5f) / float(mapSize);
        const float s = std::sin(6.28f * (3.f * u + 2.f * v) + 3.f * drive[0]);
        p.normalMap.xy[2 * (y * mapSize + x)] = 0.3f * drive[2] * s;
        p.normalMap.xy[2 * (y * mapSize + x) + 1] = 0.2f * drive[1] * s;
      }
    p.residuals.converged = true;
    ds.poses.push_back(std::move(p));
  }
  return ds;
}

// Part 2 settings small enough for the synthetic dataset (3 displacement fields, 160 poses).
BakeTrainSettings smallTraining() {
  BakeTrainSettings st;
  st.meshComponents = 6;
  st.mlp.hiddenLayers = 3;
  st.mlp.maxEpochs = 400;
  st.mlp.patience = 80;
  st.testFraction = 0.1;
  return st;
}
// A few epochs and the default recipe's anchors: uncalibrated, 6 mm, with the third (cover) set.
BakeTrainSettings uncalibratedCoverAnchors(int epochs) {
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 0;
  st.mlp.maxEpochs = epochs;
  st.calibrateAnchors = false;
  st.anchorMargin = 0.006f;
  st.coverAnchors = true;
  return st;
}
}  // namespace

TEST(BakePart2, SyntheticDatasetToLoadableModelAndReport) {
  const uint64_t seed = test::testSeed(501);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 160, 32);
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 4;
  st.databaseSize = 24;
  st.vq.codebookSize = 128;
  const BakeTrainOutput out = trainBake(ds, st);

  EXPECT_EQ(out.testPoses.size(), 16u);
  EXPECT_EQ(out.meshPca.components(), 3);  // the data has 3 displacement fields
  EXPECT_NEAR(out.meshPca.explainedVariance[3], 1.0, 1e-4);
  EXPECT_LT(out.evaluation.truncationMm.max, 0.05);  // rank 3 data, 3 components: only float round-off
  EXPECT_LT(out.evaluation.totalMm.mean, 2.0);       // the MLP learns the smooth drive
  EXPECT_GT(out.evaluation.totalMm.mean, 0.0);
  // The baselines on the same poses: skinning alone misses the displacements the network predicts; the
  // PCA mean shape holds their average only.
  EXPECT_GT(out.evaluation.restSkinnedMm.mean, 2.0 * out.evaluation.totalMm.mean);
  EXPECT_GT(out.evaluation.meanSkinnedMm.mean, 2.0 * out.evaluation.totalMm.mean);
  EXPECT_LE(out.evaluation.normalTotal.meanDegrees, out.evaluation.normalSelection.meanDegrees + 1.5);
  EXPECT_EQ(out.model.normalMaps.mapCount(), 24u);

  const test::TempDir tmp("bake_part2_" + std::to_string(seed));
  const auto dir = tmp / "report";  // not there yet: writeBakeReport makes it
  const auto md = writeBakeReport(out, ds, dir);
  EXPECT_TRUE(std::filesystem::exists(md));
  EXPECT_TRUE(std::filesystem::exists(dir / "report.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "error_vs_k.svg"));
  EXPECT_TRUE(std::filesystem::exists(dir / "training_curve.svg"));
  EXPECT_FALSE(std::filesystem::is_empty(dir / "gallery"));
  const auto report = nlohmann::json::parse(std::ifstream(dir / "report.json"));
  EXPECT_DOUBLE_EQ(report["vertex_error_held_out"]["total"]["mean_mm"].get<double>(), out.evaluation.totalMm.mean);
  EXPECT_DOUBLE_EQ(report["vertex_error_held_out"]["baseline_rest_skinned"]["p95_mm"].get<double>(),
                   out.evaluation.restSkinnedMm.p95);

  // The quality levels on the same held-out poses through the same path: the full level is the model's
  // error above, the skinned level the mean-shape baseline; the report has the section, its plot and the
  // JSON; the model carries the ladder without the times (its bytes follow from the recipe).
  const runtime::QualityLadder& ladder = out.ladder;
  ASSERT_EQ(ladder.size(), 3u);  // K = 3: full, k1 (maps), skinned (K/4 = K/8 = 0 is the skinned level)
  EXPECT_EQ(ladder.poses, 16u);
  EXPECT_EQ(ladder.levels[0].name, "full");
  EXPECT_DOUBLE_EQ(ladder.levels[0].vertexMeanMm, out.evaluation.totalMm.mean);
  EXPECT_DOUBLE_EQ(ladder.levels[0].vertexP95Mm, out.evaluation.totalMm.p95);
  EXPECT_DOUBLE_EQ(ladder.levels[0].vertexMaxMm, out.evaluation.totalMm.max);
  EXPECT_DOUBLE_EQ(ladder.levels[0].normalMeanDeg, out.evaluation.normalTotal.meanDegrees);
  EXPECT_EQ(ladder.levels.back().meshComponents, 0u);
  EXPECT_DOUBLE_EQ(ladder.levels.back().vertexMeanMm, out.evaluation.meanSkinnedMm.mean);
  EXPECT_GT(ladder.levels[0].cpuUsPerCharacter, 0.0);
  EXPECT_EQ(ladder.levels.back().cpuUsPerCharacter, 0.0);
  EXPECT_FALSE(ladder.timedOn.empty());
  EXPECT_TRUE(std::filesystem::exists(dir / "quality_levels.svg"));
  EXPECT_EQ(report["quality_levels"]["levels"].size(), ladder.size());
  EXPECT_DOUBLE_EQ(report["quality_levels"]["levels"][0]["vertex_mean_mm"].get<double>(), out.evaluation.totalMm.mean);
  EXPECT_TRUE(report["quality_levels"]["problems"].is_array());
  {
    std::ifstream mdIn(md);
    const std::string text((std::istreambuf_iterator<char>(mdIn)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("## Quality levels"), std::string::npos);
    EXPECT_NE(text.find("| full | 3 | yes |"), std::string::npos) << text;
  }

  // Held-out subjects (part1.holdout): the same levels on their frames, beside the random ones in the
  // report. Their stand-in: 16 more poses of the same synthetic character (same seed, drawn after).
  {
    const Dataset more = syntheticDataset(seed, 176, 32);
    Dataset holdout;
    holdout.character = more.character;
    holdout.inputJoints = more.inputJoints;
    holdout.poses.assign(more.poses.begin() + 160, more.poses.end());
    nlohmann::json origins = nlohmann::json::array();
    for (auto& p : holdout.poses) {
      p.id = uint32_t(origins.size());
      origins.push_back({{"clip", "99_01"}, {"subject", "99"}});
    }
    const SubjectEvaluation subjects = evaluateHeldOutSubjects(out, ds, holdout, origins, {"99"}, 16);
    ASSERT_TRUE(subjects.levels.measured());
    ASSERT_EQ(subjects.levels.size(), ladder.size());
    EXPECT_EQ(subjects.levels.poses, 16u);
    EXPECT_DOUBLE_EQ(subjects.levels.levels[0].vertexMeanMm, subjects.overall.totalMm.mean);
    EXPECT_DOUBLE_EQ(subjects.levels.levels.back().vertexMeanMm, subjects.overall.meanSkinnedMm.mean);
    EXPECT_TRUE(std::isnan(subjects.levels.levels[0].cpuUsPerCharacter));  // it goes into the metadata too
    EXPECT_TRUE(subjects.toJson().contains("quality_levels"));
    // The part of the subject's error that is the same in all its frames: never more than the error
    // (|mean of e| <= mean of |e|), and not 0 on 16 poses of a network that does not fit them exactly.
    ASSERT_EQ(subjects.perSubject.size(), 1u);
    EXPECT_EQ(subjects.perSubject[0].subject, "99");
    EXPECT_EQ(subjects.perSubject[0].poses, 16u);
    EXPECT_GT(subjects.perSubject[0].systematicMm, 0.0);
    EXPECT_LE(subjects.perSubject[0].systematicMm, subjects.perSubject[0].errorMm * (1 + 1e-9));
    EXPECT_GT(subjects.perSubject[0].errorMm, 0.0);
    EXPECT_EQ(subjects.toJson()["per_subject_systematic"][0]["systematic_mm"].get<double>(),
              subjects.perSubject[0].systematicMm);
    // The same figures per skinning joint's vertices: a partition of the game mesh (each vertex with its
    // strongest joint), so the vertex-weighted means give the whole-garment figures back.
    {
      const SubjectEvaluation::Subject& x = subjects.perSubject[0];
      ASSERT_GE(x.byJoint.size(), 2u);
      size_t vertices = 0;
      double error = 0, systematic = 0;
      for (const SubjectEvaluation::Subject::Region& r : x.byJoint) {
        EXPECT_GT(r.vertices, 0u) << r.joint;
        EXPECT_GE(out.model.skeleton.find(r.joint), 0) << r.joint;
        EXPECT_LE(r.systematicMm, r.errorMm * (1 + 1e-9)) << r.joint;
        vertices += r.vertices;
        error += r.errorMm * double(r.vertices);
        systematic += r.systematicMm * double(r.vertices);
      }
      EXPECT_EQ(vertices, out.model.gameMesh.vertexCount());
      EXPECT_NEAR(error / double(vertices), x.errorMm, 1e-9 * x.errorMm);
      EXPECT_NEAR(systematic / double(vertices), x.systematicMm, 1e-9 * x.systematicMm);
      EXPECT_EQ(subjects.toJson()["per_subject_systematic"][0]["by_joint"].size(), x.byJoint.size());
    }
    const auto sdir = tmp / "report_subjects";
    const auto smd = writeBakeReport(out, ds, sdir, 0, &subjects);
    const auto sreport = nlohmann::json::parse(std::ifstream(sdir / "report.json"));
    EXPECT_EQ(sreport["quality_levels"]["held_out_subjects"]["levels"].size(), ladder.size());
    std::ifstream mdIn(smd);
    const std::string text((std::istreambuf_iterator<char>(mdIn)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("held-out subjects mean mm"), std::string::npos) << text;
    EXPECT_NE(text.find("| joint | vertices | subject 99 |"), std::string::npos) << text;
    EXPECT_NE(text.find("| subject | poses | error mm (pre-skinning) | the same in every frame mm | share |"),
              std::string::npos)
        << text;
    // Their frames against the body too, beside the random frames: penetration of truth and model, and
    // the error with the push-out (the model has anchors).
    ASSERT_TRUE(subjects.overall.penetrationMeasured);
    EXPECT_TRUE(subjects.overall.pushOut);
    EXPECT_EQ(subjects.overall.modelPenetration.frames, subjects.overall.poses);
    EXPECT_EQ(subjects.overall.pushedPenetration.frames, subjects.overall.poses);
    EXPECT_GT(subjects.overall.totalPushedMm.mean, 0.0);
    EXPECT_DOUBLE_EQ(sreport["held_out_subjects"]["penetration"]["vertex_total_pushed"]["mean_mm"].get<double>(),
                     subjects.overall.totalPushedMm.mean);
    EXPECT_NE(text.find("| held-out subjects | model after the run-time push-out |"), std::string::npos) << text;
    EXPECT_NE(text.find("Vertex error with the push-out, held-out subjects: mean "), std::string::npos) << text;
  }

  saveModel(out.model, dir / "synthetic.swish");
  const Model loaded = loadModel(dir / "synthetic.swish");
  EXPECT_EQ(loaded.metadata, out.model.metadata);
  const auto meta = nlohmann::json::parse(loaded.metadata);
  // The push-out's body anchors: fitted to the dataset's body and calibrated on the training poses.
  EXPECT_EQ(loaded.bodyAnchors.anchors.size(), loaded.gameMesh.vertexCount());
  EXPECT_GT(loaded.bodyAnchors.anchored(), 0u);
  EXPECT_EQ(meta["body_anchors"]["calibration"]["poses"], out.trainingPoses.size());
  EXPECT_LE(meta["body_anchors"]["calibration"]["vertex_mean_mm_with"].get<double>(),
            meta["body_anchors"]["calibration"]["vertex_mean_mm_without"].get<double>() + 1e-9);
  EXPECT_TRUE(meta.contains("errors"));
  const runtime::QualityLadder carried = runtime::ladderOf(loaded);
  ASSERT_TRUE(meta.contains(runtime::kQualityLevelsKey));
  ASSERT_EQ(carried.size(), ladder.size());
  EXPECT_EQ(carried.poses, 16u);
  EXPECT_NE(carried.measuredOn.find("held-out"), std::string::npos) << carried.measuredOn;
  for (size_t i = 0; i < carried.size(); ++i) {
    EXPECT_EQ(carried.levels[i].name, ladder.levels[i].name);
    EXPECT_DOUBLE_EQ(carried.levels[i].vertexMeanMm, ladder.levels[i].vertexMeanMm);
    EXPECT_DOUBLE_EQ(carried.levels[i].normalMeanDeg, ladder.levels[i].normalMeanDeg);
    EXPECT_TRUE(std::isnan(carried.levels[i].cpuUsPerCharacter));  // times: the report's, not the model's
  }
  EXPECT_TRUE(carried.timedOn.empty());
  // The loaded model runs through the runtime: MLP -> novelty guard -> reference frame (PCA, skinning,
  // frames, VQ, blend).
  ASSERT_FALSE(loaded.noveltyGuard.empty());
  const runtime::MlpEvaluator mlp(loaded);
  const runtime::NoveltyGuardEvaluator guard(loaded);
  const DatasetPose& p = ds.poses[out.testPoses[0]];
  const auto theta = runtime::computeTheta(loaded.inputJoints, p.pose.local);
  std::vector<float> lambda(size_t(mlp.outputSize()));
  mlp.evaluate(theta, lambda);
  guard.apply(guard.measureOne(theta), std::span<float>(lambda.data(), size_t(loaded.meshComponents())));
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.meshWeights.assign(lambda.begin(), lambda.begin() + loaded.meshComponents());
  in.skinMatrices = loaded.skeleton.skinningMatrices(p.pose);
  in.selectedMaps = {out.evaluation.perPose[0].selectedMap};
  in.blendAlpha = {1.f};
  in.pushOut = false;  // perPose measures the network's garment; the push-out's figures are pooled apart
  const auto frame = runtime::referenceFrame(loaded, in);
  ASSERT_EQ(frame.positions.size(), 1u);
  double err = 0.0;
  for (Eigen::Index v = 0; v < frame.positions[0].rows(); ++v)
    err += (frame.positions[0].row(v) - p.gameMeshWorld.row(v)).norm();
  err = 1000.0 * err / double(frame.positions[0].rows());
  EXPECT_NEAR(err, out.evaluation.perPose[0].meanMm, 1e-3);  // same path, same answer
}

// train.input_joints: the network reads the joints it names, in that order, instead of the dataset's.
// The synthetic shape follows Theta of all three dataset joints, so a network given only the third
// cannot learn it, and one given all three (named in another order) can; unknown or repeated names are
// errors that say so.
TEST(BakePart2, NetworkInputJointsReplaceTheDatasets) {
  const uint64_t seed = test::testSeed(502);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 160, 32);
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 0;
  const auto& joints = ds.character.skeleton.joints;
  const std::string j0 = joints[ds.inputJoints[0]].name, j1 = joints[ds.inputJoints[1]].name,
                    j2 = joints[ds.inputJoints[2]].name;

  st.inputJoints = {j2, j0, j1};
  const BakeTrainOutput all = trainBake(ds, st);
  EXPECT_EQ(all.model.inputJoints, (std::vector<uint32_t>{ds.inputJoints[2], ds.inputJoints[0], ds.inputJoints[1]}));
  EXPECT_EQ(all.model.thetaSize(), 18);
  EXPECT_EQ(nlohmann::json::parse(all.model.metadata)["settings"]["input_joints"], nlohmann::json({j2, j0, j1}));

  // The third joint alone drives only the smallest of the three fields (a third of the first's size).
  st.inputJoints = {j2};
  const BakeTrainOutput third = trainBake(ds, st);
  EXPECT_EQ(third.model.inputJoints, (std::vector<uint32_t>{ds.inputJoints[2]}));
  EXPECT_LT(all.evaluation.regressionMm.mean, 0.5 * third.evaluation.regressionMm.mean)
      << all.evaluation.regressionMm.mean << " vs " << third.evaluation.regressionMm.mean;

  st.inputJoints = {j0, "NoSuchJoint"};
  EXPECT_NE(test::errorOf([&] {
              trainBake(ds, st);
            }).find("train.input_joints: the character 'synthetic' has no joint 'NoSuchJoint'"),
            std::string::npos);
  st.inputJoints = {j0, j1, j0};
  EXPECT_NE(test::errorOf([&] { trainBake(ds, st); }).find("joint '" + j0 + "' is named twice"), std::string::npos);
}

// train.anchor_margin_mm: uncalibrated anchors keep the recipe's margin, which the model carries through
// its file (the run-time push-out reads it per anchor as the clearance) and its metadata records; with
// train.cover_anchors the third set is fitted on the training poses too, at the same margin.
TEST(BakePart2, UncalibratedAnchorsKeepTheRecipesMargin) {
  const uint64_t seed = test::testSeed(504);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 80, 32);
  const BakeTrainSettings st = uncalibratedCoverAnchors(20);
  const BakeTrainOutput out = trainBake(ds, st);
  const test::TempDir tmp("bake_part2_margin_" + std::to_string(seed));
  saveModel(out.model, tmp / "m.swish");
  const Model loaded = loadModel(tmp / "m.swish");
  EXPECT_FLOAT_EQ(loaded.bodyAnchors.margin, 0.006f);
  ASSERT_GT(loaded.bodyAnchors.anchored(), 0u);
  for (const BodyAnchor& a : loaded.bodyAnchors.anchors) {
    if (a.present()) {
      ASSERT_FLOAT_EQ(a.clearance, 0.006f);
    }
  }
  const auto meta = nlohmann::json::parse(loaded.metadata);
  EXPECT_EQ(meta["settings"]["anchor_margin_mm"].get<double>(), 6.0);
  EXPECT_EQ(meta["body_anchors"]["margin_mm"].get<double>(), 6.0);
  EXPECT_EQ(meta["settings"]["cover_anchors"], true);
  EXPECT_GT(loaded.bodyAnchors.anchored(2), 0u) << "the synthetic poses slide the cloth over the body";
  EXPECT_EQ(loaded.bodyAnchors.anchored(2), meta["body_anchors"]["cover_anchored"].get<size_t>());
  EXPECT_LE(meta["body_anchors"]["cover_covered"].get<size_t>(), meta["body_anchors"]["cover_misses"].get<size_t>());
  for (const BodyAnchor& a : loaded.bodyAnchors.third)
    if (a.present()) {
      ASSERT_FLOAT_EQ(a.clearance, 0.006f);
    }
  std::printf("cover anchors: %zu of %zu vertices (%zu misses)\n", loaded.bodyAnchors.anchored(2),
              loaded.gameMesh.vertexCount(), meta["body_anchors"]["cover_misses"].get<size_t>());
}

// train.anchor_poses "as_played": the slide and cover anchors are fitted on each frame's nearest training
// pose, repeats kept and in the frames' order, instead of on the training poses. The frames here are two
// training poses (one of them three times, the other turned by a hair): the model's anchors are what the
// fit gives on exactly those four poses, and its metadata says where they came from.
TEST(BakePart2, AnchorsAsPlayedAreFittedOnEachFramesNearestTrainingPose) {
  const uint64_t seed = test::testSeed(506);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 80, 32);
  BakeTrainSettings st = uncalibratedCoverAnchors(5);
  const BakeTrainOutput training = trainBake(ds, st);
  ASSERT_GT(training.trainingPoses.size(), 12u);
  const DatasetPose& a = ds.poses[training.trainingPoses[3]];
  const DatasetPose& b = ds.poses[training.trainingPoses[11]];
  Pose bTurned = b.pose;
  for (uint32_t j : ds.inputJoints)
    bTurned.local[j] = (bTurned.local[j] * Quatf(Eigen::AngleAxisf(1e-3f, Vec3f::UnitY()))).normalized();
  const std::vector<Pose> frames = {a.pose, bTurned, a.pose, a.pose};

  st.anchorsAsPlayed = true;
  const BakeTrainOutput played = trainBake(ds, st, {}, frames);
  EXPECT_EQ(played.trainingPoses, training.trainingPoses);  // the same split: only the anchors' poses differ
  const auto meta = nlohmann::json::parse(played.model.metadata)["body_anchors"];
  EXPECT_EQ(meta["poses_from"], "as_played");
  EXPECT_EQ(meta["as_played"]["frames"], 4);
  EXPECT_EQ(meta["as_played"]["distinct_training_poses"], 2);
  EXPECT_LT(meta["as_played"]["theta_distance_max"].get<double>(), 0.01);
  EXPECT_EQ(meta["slide_poses"], 4);
  EXPECT_EQ(nlohmann::json::parse(training.model.metadata)["body_anchors"]["poses_from"], "training");

  BodyAnchorFitSettings fs;
  fs.margin = st.anchorMargin;
  fs.coverAnchors = true;
  std::vector<BodyAnchorSlidePose> byHand;
  for (const DatasetPose* p : {&a, &b, &a, &a})
    byHand.push_back({played.model.skeleton.skinningMatrices(p->pose), &p->gameMeshWorld});
  const BodyAnchorFit fit = fitBodyAnchors(ds.character.body, played.model.skeleton, played.model.gameMesh, fs, byHand);
  const BodyAnchors& got = played.model.bodyAnchors;
  auto same = [](const std::vector<BodyAnchor>& x, const std::vector<BodyAnchor>& y, const char* set) {
    ASSERT_EQ(x.size(), y.size()) << set;
    for (size_t v = 0; v < x.size(); ++v) {
      ASSERT_EQ(x[v].position, y[v].position) << set << " anchor of vertex " << v;
      ASSERT_EQ(x[v].radius, y[v].radius) << set << " anchor of vertex " << v;
      ASSERT_EQ(x[v].joints, y[v].joints) << set << " anchor of vertex " << v;
      ASSERT_EQ(x[v].weights, y[v].weights) << set << " anchor of vertex " << v;
    }
  };
  same(got.anchors, fit.anchors.anchors, "first");
  same(got.second, fit.anchors.second, "second");
  same(got.third, fit.anchors.third, "third");
  ASSERT_GT(got.anchored(2), 0u) << "the synthetic poses slide the cloth over the body";
  // ... and not what the training poses give (the four poses are not the fit's 400).
  bool differs = training.model.bodyAnchors.third.size() != got.third.size();
  for (size_t v = 0; !differs && v < got.third.size(); ++v)
    differs = training.model.bodyAnchors.third[v].position != got.third[v].position;
  EXPECT_TRUE(differs);

  // Calibrated (train.anchor_calibration "strict"): the anchors fitted on the frames' poses are calibrated on
  // the training poses, each with its own skinning (not the fit's list, which is another length and order).
  {
    BakeTrainSettings strict = st;
    strict.calibrateAnchors = true;
    const BakeTrainOutput calibrated = trainBake(ds, strict, {}, frames);
    BodyAnchors byHandCalibrated = fit.anchors;
    std::vector<Points3f> predicted(calibrated.trainingPoses.size());
    std::vector<BodyAnchorCalibrationPose> cal;
    for (size_t i = 0; i < calibrated.trainingPoses.size(); ++i) {
      const DatasetPose& p = ds.poses[calibrated.trainingPoses[i]];
      predicted[i] = predictPositions(calibrated.model, p.pose, false);
      cal.push_back({calibrated.model.skeleton.skinningMatrices(p.pose), &p.gameMeshWorld, &predicted[i]});
    }
    calibrateBodyAnchors(byHandCalibrated, cal);
    const BodyAnchors& c = calibrated.model.bodyAnchors;
    ASSERT_EQ(c.anchors.size(), byHandCalibrated.anchors.size());
    for (size_t v = 0; v < c.anchors.size(); ++v)
      ASSERT_EQ(c.anchors[v].clearance, byHandCalibrated.anchors[v].clearance) << "first anchor of vertex " << v;
    ASSERT_EQ(c.third.size(), byHandCalibrated.third.size());
    for (size_t v = 0; v < c.third.size(); ++v)
      ASSERT_EQ(c.third[v].clearance, byHandCalibrated.third[v].clearance) << "third anchor of vertex " << v;
  }

  // Frames without the setting, or the setting without frames, are mistakes that say so.
  EXPECT_NE(test::errorOf([&] { trainBake(ds, st); }).find("needs frames of the training clips"), std::string::npos);

  // "simulated": the frames' own shapes (a dataset of them; here three of the poses, one a held-out one)
  // instead of their nearest training poses'.
  Dataset shapes;
  shapes.character = ds.character;
  shapes.inputJoints = ds.inputJoints;
  for (uint32_t i : {training.trainingPoses[5], training.testPoses[0], training.trainingPoses[7]})
    shapes.poses.push_back(ds.poses[i]);
  st.anchorFramesSimulated = true;
  EXPECT_NE(test::errorOf([&] { trainBake(ds, st, {}, frames); }).find("needs the frames' simulations"),
            std::string::npos);
  const BakeTrainOutput simulated = trainBake(ds, st, {}, {}, &shapes);
  const auto simMeta = nlohmann::json::parse(simulated.model.metadata)["body_anchors"];
  EXPECT_EQ(simMeta["as_played"]["simulated"], true);
  EXPECT_EQ(simMeta["as_played"]["frames"], 3);
  EXPECT_EQ(simMeta["slide_poses"], 3);
  std::vector<BodyAnchorSlidePose> simByHand;
  for (const DatasetPose& p : shapes.poses)
    simByHand.push_back({simulated.model.skeleton.skinningMatrices(p.pose), &p.gameMeshWorld});
  const BodyAnchorFit simFit =
      fitBodyAnchors(ds.character.body, simulated.model.skeleton, simulated.model.gameMesh, fs, simByHand);
  same(simulated.model.bodyAnchors.second, simFit.anchors.second, "second (simulated frames)");
  same(simulated.model.bodyAnchors.third, simFit.anchors.third, "third (simulated frames)");

  st.anchorsAsPlayed = false;
  EXPECT_NE(test::errorOf([&] { trainBake(ds, st, {}, frames); }).find("train.anchor_poses is \"training\""),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { trainBake(ds, st, {}, {}, &shapes); }).find("train.anchor_poses is \"training\""),
            std::string::npos);
}

// train.root_gravity: a shape that follows the root's lean, which no input joint's local rotation holds,
// is learnt with the gravity values in Theta and not without them; the model carries them through its
// file, and its own evaluation (the run-time path) reads them.
TEST(BakePart2, TheRootsLeanIsLearntWithTheGravityValues) {
  const uint64_t seed = test::testSeed(503);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 160, 32, true);
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 0;
  const auto& joints = ds.character.skeleton.joints;
  ASSERT_EQ(ds.inputJoints.front(), 0u);  // the root: the network must not read it as a joint
  st.inputJoints = {joints[ds.inputJoints[1]].name, joints[ds.inputJoints[2]].name, joints[ds.inputJoints[3]].name};
  const BakeTrainOutput without = trainBake(ds, st);
  st.rootGravity = true;
  const BakeTrainOutput with = trainBake(ds, st);
  EXPECT_FALSE(without.model.rootGravity);
  EXPECT_TRUE(with.model.rootGravity);
  EXPECT_EQ(without.model.thetaSize(), 18);
  EXPECT_EQ(with.model.thetaSize(), 21);
  EXPECT_EQ(with.model.noveltyGuard.centres.cols(), 21);
  EXPECT_EQ(nlohmann::json::parse(with.model.metadata)["settings"]["root_gravity"], true);
  EXPECT_FALSE(nlohmann::json::parse(without.model.metadata)["settings"].contains("root_gravity"));
  std::printf("regression error on held-out poses: %.3f mm with the gravity values, %.3f mm without\n",
              with.evaluation.regressionMm.mean, without.evaluation.regressionMm.mean);
  EXPECT_LT(with.evaluation.regressionMm.mean, 0.5 * without.evaluation.regressionMm.mean);
  const Model back = deserializeModel(serializeModel(with.model), "with gravity");
  EXPECT_TRUE(back.rootGravity);
  EXPECT_EQ(back.inputJoints, with.model.inputJoints);
  // Part 1's datasets have every pose upright (the root at its rest rotation, canonicalPose): the gravity
  // values would be one constant, and the run time would feed the network leans its truth never had.
  // Turned about the vertical only, the values are as constant.
  Dataset upright = ds;
  for (size_t i = 0; i < upright.poses.size(); ++i)
    upright.poses[i].pose.local[0] = Quatf(Eigen::AngleAxisf(0.01f * float(i), Vec3f::UnitY()));
  EXPECT_NE(test::errorOf([&] {
              trainBake(upright, st);
            }).find("train.root_gravity: every training pose of the dataset has its root joint at one lean"),
            std::string::npos);
}

// Synthesized poses (part1.synthesis, ids from the dataset's synthesized_from_id on) are trained on and
// never held out: the random held-out poses stay recorded frames, as many as without them, and mostly the
// same poses (the split is keyed by pose id).
TEST(BakePart2, SynthesizedPosesAreNeverHeldOut) {
  const uint64_t seed = test::testSeed(503);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Dataset ds = syntheticDataset(seed, 160, 32);
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 0;
  st.mlp.maxEpochs = 5;
  Dataset recordedOnly = ds;
  recordedOnly.poses.resize(120);
  const BakeTrainOutput plain = trainBake(recordedOnly, st);
  ds.settings["synthesized_from_id"] = ds.poses[120].id;  // the last 40 stand for synthesized poses
  const BakeTrainOutput out = trainBake(ds, st);
  EXPECT_EQ(out.synthesizedPoses, 40u);
  EXPECT_EQ(out.testPoses.size(), 12u);  // a tenth of the 120 recorded poses
  EXPECT_EQ(out.testPoses, plain.testPoses);
  for (uint32_t i : out.testPoses) EXPECT_LT(i, 120u);
  EXPECT_EQ(out.trainingPoses.size(), 148u);
  EXPECT_EQ(out.evaluation.poses, 12u);
}

// train.distill: the teacher's synthetic poses are trained on beside the recorded ones; the held-out split
// and the network's validation poses are those of the bake without them; the metadata and the report
// record the teacher and its error beside the network's; the recipe's settings round-trip.
TEST(BakePart2, DistillationTrainsOnTheTeachersPoses) {
  const uint64_t seed = test::testSeed(504);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Dataset ds = syntheticDataset(seed, 160, 32);
  BakeTrainSettings st = smallTraining();
  st.normalCodeDims = 0;
  const BakeTrainOutput plain = trainBake(ds, st);
  st.distill.poses = 300;
  const BakeTrainOutput out = trainBake(ds, st);
  EXPECT_EQ(out.testPoses, plain.testPoses);
  EXPECT_EQ(out.distilled.theta.cols(), 300);
  EXPECT_EQ(out.distilled.blends + out.distilled.mixes, 300u);
  EXPECT_GT(out.distilled.blends, 100u);
  EXPECT_GT(out.distilled.mixes, 100u);
  // The network's samples: the 144 training poses and the 300 synthetic ones, validated on the same
  // recorded poses as without them.
  EXPECT_EQ(out.regressor.trainingSamples.size() + out.regressor.validationSamples.size(), 444u);
  EXPECT_EQ(out.regressor.validationSamples, plain.regressor.validationSamples);
  ASSERT_TRUE(out.metadata.contains("distill"));
  const nlohmann::json& d = out.metadata["distill"];
  EXPECT_EQ(d["poses"], 300);
  EXPECT_GT(d["teacher"]["width"].get<double>(), 0.0);
  // On a smooth low-rank truth both fit well: the teacher and the network within a few mm (the synthetic
  // fields are up to 2 cm), and the comparison is the same arithmetic as compareTeacher's.
  std::vector<const DatasetPose*> held;
  for (uint32_t i : out.testPoses) held.push_back(&ds.poses[i]);
  const TeacherComparison c = compareTeacher(out, held);
  EXPECT_EQ(c.poses, out.testPoses.size());
  EXPECT_DOUBLE_EQ(d["held_out_pre_skin_mean_mm"]["teacher"].get<double>(), c.teacherMm);
  EXPECT_DOUBLE_EQ(d["held_out_pre_skin_mean_mm"]["network"].get<double>(), c.networkMm);
  EXPECT_GT(c.teacherMm, 0.0);
  EXPECT_LT(c.teacherMm, 3.0);
  EXPECT_LT(c.networkMm, 3.0);
  EXPECT_EQ(compareTeacher(plain, held).poses, 0u);  // no teacher, nothing compared
  EXPECT_FALSE(plain.metadata.contains("distill"));
  EXPECT_FALSE(plain.metadata["settings"].contains("distill"));  // older fingerprints stay
  EXPECT_EQ(out.metadata["settings"]["distill"]["poses"], 300);
  const test::TempDir tmp("bake_part2_distill_" + std::to_string(seed));
  std::ifstream md(writeBakeReport(out, ds, tmp / "report", 2));
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("**Distillation**"), std::string::npos);
}

TEST(BakePart2, RunBakeFromADatasetFolderIsResumable) {
  const uint64_t seed = test::testSeed(502);
  const Dataset ds = syntheticDataset(seed, 60, 16);
  const test::TempDir tmp("run_bake_" + std::to_string(seed));
  const auto dir = tmp / "bake";  // not there yet: the DatasetWriter and runBake make what they need
  {
    DatasetWriter w(dir / "dataset", ds.character, ds.inputJoints, ds.settings, 16);
    for (const auto& p : ds.poses) w.writePose(p);
    w.writeManifest();
  }
  const BakeConfig cfg = parseBakeConfig({{"name", "tiny"},
                                          {"output", "out"},
                                          {"dataset", "dataset"},
                                          {"train",
                                           {{"mesh_components", 4},
                                            {"normal_code_dims", 3},
                                            {"database_size", 8},
                                            {"codebook_size", 64},
                                            {"hidden_layers", 2},
                                            {"max_epochs", 60},
                                            {"patience", 20}}}},
                                         "tiny.json", dir);
  std::vector<std::string> lines;
  BakeRunOptions o;
  o.log = [&](const std::string& l) { lines.push_back(l); };
  const BakeRunResult first = runBake(cfg, o);
  EXPECT_FALSE(first.part2Skipped);
  EXPECT_TRUE(std::filesystem::exists(first.report));
  const Model m = loadModel(first.model);
  EXPECT_EQ(m.normalMaps.mapCount(), 8u);
  EXPECT_EQ(nlohmann::json::parse(m.metadata)["name"], "tiny");
  bool sawTimeLeft = false;
  for (const auto& l : lines) sawTimeLeft |= l.find("left") != std::string::npos;
  EXPECT_TRUE(sawTimeLeft);
  EXPECT_TRUE(runBake(cfg, o).part2Skipped);  // same dataset, same settings: nothing to redo
  BakeRunOptions force = o;
  force.force = true;
  EXPECT_FALSE(runBake(cfg, force).part2Skipped);
  // No dataset and no part 1 section: a clear error before any work.
  const BakeConfig none = parseBakeConfig({{"output", "o2"}}, "none.json", dir);
  EXPECT_THROW(runBake(none, o), Error);
}
