#include "swish/bake/pipeline/part2_training.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "swish/bake/compression/bc5_baseline.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/training/body_anchor_fit.hpp"
#include "swish/bake/training/distillation.hpp"
#include "swish/bake/training/model_builder.hpp"
#include "swish/bake/training/novelty_guard_fit.hpp"
#include "swish/bake/transfer/body_coverage.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

nlohmann::json BakeTrainSettings::toJson() const {
  nlohmann::json j = {{"mesh_components", meshComponents},
                      {"mesh_variance", meshVariance},
                      {"normal_code_dims", normalCodeDims},
                      {"database_size", databaseSize},
                      {"codebook_size", vq.codebookSize},
                      {"vq_training_blocks", vq.trainingBlocks},
                      {"vq_iterations", vq.iterations},
                      {"hidden_layers", mlp.hiddenLayers},
                      {"hidden_width", mlp.hiddenWidth},
                      {"activation", activationName(mlp.activation)},
                      {"learning_rate", mlp.learningRate},
                      {"batch_size", mlp.batchSize},
                      {"max_epochs", mlp.maxEpochs},
                      {"patience", mlp.patience},
                      {"validation_fraction", mlp.validationFraction},
                      {"normal_code_weight", normalCodeWeight},
                      {"mesh_weight_floor", meshWeightFloor},
                      {"max_training_seconds", mlp.maxSeconds},
                      {"test_fraction", testFraction},
                      {"temporal_time_constant", temporalTimeConstant},
                      {"seed", seed}};
  if (!inputJoints.empty()) j["input_joints"] = inputJoints;       // absent: the dataset's (older fingerprints stay)
  if (mlp.weightDecay > 0.0) j["weight_decay"] = mlp.weightDecay;  // absent when off (older fingerprints stay)
  if (mlp.inputNoise > 0.0) j["input_noise"] = mlp.inputNoise;     // likewise
  if (!calibrateAnchors) j["anchor_calibration"] = "none";         // likewise
  if (rootGravity) j["root_gravity"] = true;                       // likewise
  if (anchorMargin != BodyAnchorFitSettings{}.margin)  // likewise; in micrometres' steps, as the recipe writes it
    j["anchor_margin_mm"] = std::round(1e6 * double(anchorMargin)) / 1e3;
  if (coverAnchors) j["cover_anchors"] = true;  // likewise
  if (anchorsAsPlayed) {                        // likewise
    j["anchor_poses"] = {{"from", "as_played"}, {"frames", anchorFramesAsPlayed}};
    if (anchorFramesSimulated) j["anchor_poses"]["simulated"] = true;
  }
  if (distill.poses > 0)  // likewise
    j["distill"] = {{"poses", distill.poses},
                    {"mix_share", distill.mixShare},
                    {"swap_probability", distill.swapProbability},
                    {"neighbours", distill.neighbours}};
  return j;
}

namespace {
using Clock = std::chrono::steady_clock;

// train.anchor_poses "as_played": per frame, the training pose nearest it (Euclidean in the network's
// Theta, `trainingTheta`'s columns; ties to the lower index), repeats kept.
struct AnchorPosesAsPlayed {
  std::vector<uint32_t> trainingIndex;  // per frame, a column of trainingTheta
  size_t distinct = 0;
  double medianDistance = 0.0, maxDistance = 0.0;
};
AnchorPosesAsPlayed nearestTrainingPoses(const MatXf& trainingTheta, const std::vector<uint32_t>& thetaJoints,
                                         bool rootGravity, std::span<const Pose> frames) {
  AnchorPosesAsPlayed out;
  if (trainingTheta.cols() == 0) throw Error("bake: train.anchor_poses \"as_played\": no training pose");
  std::vector<double> distances;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (uint32_t j : thetaJoints)
      if (j >= frames[f].local.size() || !frames[f].local[j].coeffs().allFinite())
        throw Error("bake: train.anchor_poses \"as_played\": frame " + std::to_string(f) +
                    " lacks a finite rotation of input joint " + std::to_string(j));
    const std::vector<float> th = runtime::computeTheta(thetaJoints, rootGravity, frames[f].local);
    const Eigen::Map<const VecXf> x(th.data(), Eigen::Index(th.size()));
    Eigen::Index best = 0;
    const float d2 = (trainingTheta.colwise() - x).colwise().squaredNorm().minCoeff(&best);
    out.trainingIndex.push_back(uint32_t(best));
    distances.push_back(std::sqrt(double(d2)));
  }
  std::vector<uint32_t> sorted = out.trainingIndex;
  std::sort(sorted.begin(), sorted.end());
  out.distinct = size_t(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
  if (!distances.empty()) {
    std::sort(distances.begin(), distances.end());
    out.medianDistance = distances[distances.size() / 2];
    out.maxDistance = distances.back();
  }
  return out;
}
}  // namespace

std::vector<uint32_t> networkInputJoints(const Dataset& ds, const BakeTrainSettings& st) {
  if (st.inputJoints.empty()) return ds.inputJoints;
  std::vector<uint32_t> out;
  for (const std::string& name : st.inputJoints) {
    const int j = ds.character.skeleton.find(name);
    if (j < 0)
      throw Error("bake: train.input_joints: the character '" + ds.character.name + "' has no joint '" + name + "'");
    if (std::find(out.begin(), out.end(), uint32_t(j)) != out.end())
      throw Error("bake: train.input_joints: joint '" + name + "' is named twice");
    out.push_back(uint32_t(j));
  }
  return out;
}

TeacherComparison compareTeacher(const BakeTrainOutput& out, const std::vector<const DatasetPose*>& poses) {
  TeacherComparison c;
  if (poses.empty() || out.distilled.teacher.centres.cols() == 0) return c;
  const Model& m = out.model;
  const int K = out.meshPca.components();
  const size_t n = size_t(out.meshPca.mean.size() / 3);
  MatXf theta(Eigen::Index(thetaSize(m.inputJoints.size(), m.rootGravity)), Eigen::Index(poses.size()));
  for (size_t i = 0; i < poses.size(); ++i) {
    const std::vector<float> th = runtime::computeTheta(m.inputJoints, m.rootGravity, poses[i]->pose.local);
    theta.col(Eigen::Index(i)) = Eigen::Map<const VecXf>(th.data(), Eigen::Index(th.size()));
  }
  const MatXf teacherShapes = out.meshPca.reconstruct(out.distilled.teacher.predict(theta).topRows(K));
  for (size_t i = 0; i < poses.size(); ++i) {
    const Points3f& truth = poses[i]->gameMeshPreSkin;
    // The network's side as the report's own pre-skinning figures take it (subject_evaluation.cpp).
    c.networkMm += (predictPreSkin(m, poses[i]->pose) - truth).rowwise().norm().sum();
    for (size_t v = 0; v < n; ++v)
      c.teacherMm +=
          (teacherShapes.col(Eigen::Index(i)).segment<3>(Eigen::Index(3 * v)) - truth.row(Eigen::Index(v)).transpose())
              .norm();
  }
  const double count = double(poses.size() * n);
  c.teacherMm *= 1000.0 / count, c.networkMm *= 1000.0 / count;
  c.poses = poses.size();
  return c;
}

BakeTrainOutput trainBake(const Dataset& ds, const BakeTrainSettings& st, const BakeProgress& progress,
                          std::span<const Pose> anchorFrames, const Dataset* anchorFrameShapes) {
  auto report = [&](const std::string& s, double f) {
    if (progress) progress(s, f);
  };
  const bool simulatedFrames = st.anchorsAsPlayed && st.anchorFramesSimulated;
  if (simulatedFrames && (!anchorFrameShapes || anchorFrameShapes->poses.empty()))
    throw Error(
        "bake: train.anchor_poses \"as_played\" with \"simulated\" needs the frames' simulations (part 1 "
        "makes them; none were given)");
  if (simulatedFrames && anchorFrameShapes->character.garment.vertexCount() != ds.character.garment.vertexCount())
    throw Error("bake: the anchor frames' dataset has another game mesh than the training dataset's");
  if (st.anchorsAsPlayed && !simulatedFrames && anchorFrames.empty())
    throw Error(
        "bake: train.anchor_poses \"as_played\" needs frames of the training clips (a bake reads them from "
        "part1.clips; this one has none)");
  if (!st.anchorsAsPlayed && (!anchorFrames.empty() || anchorFrameShapes))
    throw Error("bake: frames as played were given for the anchors, but train.anchor_poses is \"training\"");
  if (!simulatedFrames && anchorFrameShapes)
    throw Error("bake: simulated anchor frames were given, but train.anchor_poses does not say \"simulated\"");
  const size_t poses = ds.poses.size();
  if (poses < 3) throw Error("bake: the dataset has " + std::to_string(poses) + " poses; training needs at least 3");
  if (ds.inputJoints.empty()) throw Error("bake: the dataset names no input joints (Theta)");
  const std::vector<uint32_t> thetaJoints = networkInputJoints(ds, st);
  const size_t n = ds.character.garment.vertexCount();
  for (const auto& p : ds.poses)
    if (size_t(p.gameMeshPreSkin.rows()) != n || size_t(p.gameMeshWorld.rows()) != n)
      throw Error("bake: pose " + std::to_string(p.id) + " has " + std::to_string(p.gameMeshPreSkin.rows()) +
                  " game-mesh vertices, the character's game mesh has " + std::to_string(n));
  if (!(st.testFraction >= 0.0 && st.testFraction < 0.5)) throw Error("bake: test fraction must be in [0, 0.5)");

  BakeTrainOutput out;
  auto t = Clock::now();
  auto stage = [&](const std::string& name) {
    const auto now = Clock::now();
    out.stages.push_back({name, std::chrono::duration<double>(now - t).count()});
    t = now;
  };

  // Held-out split, keyed by pose id (mlp_trainer.hpp, keyedSplit): a re-bake whose part 1 kept a few more
  // or fewer poses holds out the same poses of the rest, so two bakes' held-out figures compare pose for
  // pose instead of on two random samples. The rest pose part 1 added (part1_dataset.hpp) is always
  // trained on, never held out: it is there so that the network knows the A-pose, not to be measured.
  std::vector<uint32_t>& pinned = out.pinnedPoses;
  const bool hasRest = ds.settings.is_object() && ds.settings.contains("rest_pose_id") &&
                       ds.settings["rest_pose_id"].is_number_integer();
  const int64_t restId = hasRest ? ds.settings["rest_pose_id"].get<int64_t>() : int64_t(-1);
  // Synthesized poses (part1.synthesis, the ids from synthesized_from_id on) are never held out either (they
  // may validate the MLP): the random held-out poses stay recorded frames of the training clips, as the
  // report calls them, and as many as a bake without synthesis holds out.
  const bool hasSynth = ds.settings.is_object() && ds.settings.contains("synthesized_from_id") &&
                        ds.settings["synthesized_from_id"].is_number_integer();
  const int64_t synthFrom = hasSynth ? ds.settings["synthesized_from_id"].get<int64_t>() : int64_t(-1);
  size_t synthesized = 0;
  std::vector<uint32_t> neverHeld;  // pinned, and the synthesized poses
  for (size_t i = 0; i < poses; ++i) {
    const bool rest = restId >= 0 && int64_t(ds.poses[i].id) == restId;
    const bool synth = synthFrom >= 0 && int64_t(ds.poses[i].id) >= synthFrom;
    synthesized += synth;
    if (rest) pinned.push_back(uint32_t(i));
    if (rest || synth) neverHeld.push_back(uint32_t(i));
  }
  out.synthesizedPoses = synthesized;
  Rng rng(st.seed);
  std::vector<uint64_t> poseIds(poses);
  for (size_t i = 0; i < poses; ++i) poseIds[i] = ds.poses[i].id;
  const size_t recorded = poses - synthesized;
  IndexSplit split =
      keyedSplit(poseIds, std::min(poses - 2, size_t(std::lround(st.testFraction * double(recorded)))), rng, neverHeld);
  out.testPoses = std::move(split.held);
  out.trainingPoses = std::move(split.kept);
  const size_t nTrain = out.trainingPoses.size();

  if (st.rootGravity && nTrain > 1) {
    // Part 1 simulates every pose with the root at its rest rotation (pose_shape.hpp, canonicalPose): such a
    // dataset's gravity values are one constant the network cannot learn from, and the run time would feed it
    // the recorded root's lean, which its truth never had. Refused before any fitting.
    // (A turn about the vertical changes nothing either: the values are gravity in the root's frame.) The
    // values are Theta's own: computeTheta with no input joints gives the gravity values alone.
    auto gravity = [&](uint32_t p) { return runtime::computeTheta({}, true, ds.poses[p].pose.local); };
    const std::vector<float> first = gravity(out.trainingPoses[0]);
    const bool leans = std::any_of(out.trainingPoses.begin(), out.trainingPoses.end(), [&](uint32_t p) {
      const std::vector<float> g = gravity(p);
      for (size_t k = 0; k < g.size(); ++k)
        if (std::abs(g[k] - first[k]) > 1e-6f) return true;
      return false;
    });
    if (!leans)
      throw Error(
          "train.root_gravity: every training pose of the dataset has its root joint at one lean (part 1 "
          "simulates poses upright: the root's rotation is reset to its rest rotation), so the gravity "
          "values are constant and nothing can be learnt from them; turn train.root_gravity off");
  }

  // 1. Mesh PCA in pre-skinning space.
  report("mesh PCA", 0.0);
  MatXf shapes(Eigen::Index(3 * n), Eigen::Index(nTrain));
  for (size_t i = 0; i < nTrain; ++i)
    shapes.col(Eigen::Index(i)) =
        Eigen::Map<const VecXf>(ds.poses[out.trainingPoses[i]].gameMeshPreSkin.data(), Eigen::Index(3 * n));
  PcaOptions po;
  po.maxComponents = st.meshComponents;
  po.varianceToKeep = st.meshVariance;
  po.seed = st.seed + 1;
  out.meshPca = fitPca(shapes, po, "mesh PCA");
  const MatXf meshCodes = out.meshPca.project(shapes);
  stage("mesh PCA");

  // 2. Normal maps: PCA codes, k-means database, VQ.
  const bool maps = st.normalCodeDims > 0;
  NormalMapDatabase db;
  MatXf normalCodes;
  if (maps) {
    report("normal-map PCA", 0.1);
    std::vector<const NormalMapImage*> trainMaps;
    for (uint32_t i : out.trainingPoses) trainMaps.push_back(&ds.poses[i].normalMap);
    out.normalPca = fitNormalMapPca(trainMaps, st.normalCodeDims, st.seed + 2);
    normalCodes = out.normalPca.codes;
    stage("normal-map PCA");
    report("normal-map database (k-means)", 0.25);
    out.database = selectDatabaseMaps(normalCodes, st.databaseSize, st.seed + 3);
    for (uint32_t m : out.database.mapIndices) out.databaseMaps.push_back(trainMaps[m]);
    db.keys = out.database.keys;
    stage("normal-map database");
    report("VQ codebook", 0.3);
    VqOptions vq = st.vq;
    vq.seed = st.seed + 4;
    out.vq = encodeVq(out.databaseMaps, vq, db);
    AngularErrorAccumulator vqAcc, bc5Acc;
    for (uint32_t m = 0; m < db.mapCount(); ++m) vqAcc.addMaps(*out.databaseMaps[m], decodeVqMap(db, m));
    out.vqVsUncompressed = vqAcc.stats();
    out.uncompressedBytes = uint64_t(db.mapCount()) * db.width * db.height * 2 * sizeof(float);
    stage("VQ");
    if (st.bc5Baseline) {
      for (const NormalMapImage* m : out.databaseMaps) bc5Acc.addMaps(*m, bc5RoundTrip(*m));
      out.bc5VsUncompressed = bc5Acc.stats();
      out.bc5Bytes = uint64_t(db.mapCount()) * bc5Bytes(db.width, db.height);
      const auto [w, h] =
          bc5SizeWithin(db.width, db.height, size_t(out.vq.totalBytes() / std::max<size_t>(1, db.mapCount())));
      if (w > 0) {
        AngularErrorAccumulator equalAcc;
        for (const NormalMapImage* m : out.databaseMaps) equalAcc.addMaps(*m, bc5RoundTripResized(*m, w, h));
        out.bc5AtVqMemoryVsUncompressed = equalAcc.stats();
        out.bc5AtVqMemoryWidth = w, out.bc5AtVqMemoryHeight = h;
        out.bc5AtVqMemoryBytes = uint64_t(db.mapCount()) * bc5Bytes(w, h);
      }
      stage("BC5 baseline");
    }
  }

  // 3. MLP Theta -> Lambda = [mesh weights, normal code].
  report("MLP training", 0.5);
  const int K = out.meshPca.components(), C = maps ? int(normalCodes.rows()) : 0;
  MatXf theta(Eigen::Index(thetaSize(thetaJoints.size(), st.rootGravity)), Eigen::Index(nTrain)),
      lambda(K + C, Eigen::Index(nTrain));
  for (size_t i = 0; i < nTrain; ++i) {
    const std::vector<float> th =
        runtime::computeTheta(thetaJoints, st.rootGravity, ds.poses[out.trainingPoses[i]].pose.local);
    theta.col(Eigen::Index(i)) = Eigen::Map<const VecXf>(th.data(), Eigen::Index(th.size()));
  }
  lambda.topRows(K) = meshCodes;
  if (C) lambda.bottomRows(C) = normalCodes;
  MlpTrainOptions mo = st.mlp;
  mo.seed = st.seed + 5;
  for (uint32_t p : out.trainingPoses) mo.sampleKeys.push_back(ds.poses[p].id);  // validation keyed by pose id too
  for (uint32_t p : pinned)                                                      // its column among the training poses
    mo.alwaysTrain.push_back(
        uint32_t(std::lower_bound(out.trainingPoses.begin(), out.trainingPoses.end(), p) - out.trainingPoses.begin()));
  if (mo.outputWeights.empty()) {
    // Mesh weights by their share of the shape variance (the loss then follows the vertex error),
    // mixed with st.meshWeightFloor of a uniform weight; the normal code as one block of
    // normalCodeWeight times the mesh's total weight.
    const VecXd var = out.meshPca.singularValues.head(K).cwiseAbs2();
    const double sum = std::max(var.sum(), 1e-300), uniform = st.meshWeightFloor;
    for (int k = 0; k < K; ++k) mo.outputWeights.push_back((1.0 - uniform) * var[k] / sum + uniform / K);
    for (int c = 0; c < C; ++c) mo.outputWeights.push_back(st.normalCodeWeight / C);
  }
  if (st.distill.poses > 0) {
    // train.distill (distillation.hpp): the teacher's labels for poses between and around the training
    // poses, trained on always (never validated on: early stopping judges by simulations alone).
    report("distillation teacher", 0.45);
    DistillSettings distill = st.distill;
    distill.seed = st.seed + 8;
    distill.teacher.seed = st.seed + 9;
    distill.teacher.outputWeights = mo.outputWeights;
    std::vector<const Pose*> trainingPoses;
    for (uint32_t p : out.trainingPoses) trainingPoses.push_back(&ds.poses[p].pose);
    out.distilled = distilledSamples(trainingPoses, thetaJoints, st.rootGravity, theta, lambda, distill);
    stage("distillation teacher");
    report("MLP training", 0.5);
    const Eigen::Index real = theta.cols(), extra = out.distilled.theta.cols();
    MatXf allTheta(theta.rows(), real + extra), allLambda(lambda.rows(), real + extra);
    allTheta << theta, out.distilled.theta;
    allLambda << lambda, out.distilled.lambda;
    mo.validationPool = size_t(real);
    for (Eigen::Index i = 0; i < extra; ++i) {
      mo.alwaysTrain.push_back(uint32_t(real + i));
      mo.sampleKeys.push_back((uint64_t(1) << 63) + uint64_t(i));  // past any pose id
    }
    out.regressor = trainMlp(allTheta, allLambda, mo);
  } else {
    out.regressor = trainMlp(theta, lambda, mo);
  }
  stage("MLP training");

  // 4. Model, then evaluation on the held-out poses through the runtime path.
  report("model + evaluation", 0.9);
  out.metadata = {{"generator", "swish bake"},
                  {"character", ds.character.name},
                  {"settings", st.toJson()},
                  {"dataset_settings", ds.settings},
                  {"poses", {{"training", nTrain}, {"held_out", out.testPoses.size()}}}};
  ModelParts parts;
  parts.character = &ds.character;
  parts.inputJoints = thetaJoints;
  parts.rootGravity = st.rootGravity;
  parts.regressor = &out.regressor;
  parts.meshPca = &out.meshPca;
  parts.normalMaps = db;
  parts.temporalFilter.timeConstantSeconds = st.temporalTimeConstant;
  parts.metadata = out.metadata;
  out.model = buildModel(parts);
  // The run-time novelty guard: centres and unit from the training inputs, the clamp from the training
  // shapes' weights; the blend is chosen on held-out subjects afterwards (bake_pipeline.cpp).
  NoveltyGuardFitOptions guardOptions;
  guardOptions.seed = st.seed + 7;
  out.model.noveltyGuard = fitNoveltyGuard(out.model, theta, meshCodes, guardOptions);
  out.metadata["novelty_guard"] = {{"centres", out.model.noveltyGuard.centres.rows()},
                                   {"unit", out.model.noveltyGuard.unit},
                                   {"clamp", true},
                                   {"blend", false}};
  // The run-time push-out's body anchors, fitted to the character's body (none for a body-less
  // character) and calibrated on the training poses: the network's garment there against the simulated
  // one (body_anchor_fit.hpp says why). Training poses, not the held-out ones, so that the report's
  // held-out figures of the push-out stay unbiased; the network fits its training poses closer than
  // new ones, which makes the calibration cautious (it pushes less), not bold.
  if (ds.character.body.triangleCount() > 0) {
    report("body anchors", 0.92);
    BodyAnchorFitSettings fitSettings;
    fitSettings.margin = st.anchorMargin;
    fitSettings.coverAnchors = st.coverAnchors;
    // The training poses' simulated garments show where the cloth slides over the body (the slide anchors).
    std::vector<BodyAnchorSlidePose> training(out.trainingPoses.size());
    for (size_t i = 0; i < out.trainingPoses.size(); ++i) {
      const DatasetPose& p = ds.poses[out.trainingPoses[i]];
      training[i] = {out.model.skeleton.skinningMatrices(p.pose), &p.gameMeshWorld};
    }
    // train.anchor_poses "as_played": the slide and cover anchors are fitted on each frame's nearest training
    // pose instead, in the frames' order, or on the frames' own simulations; the fit then takes all of them
    // (it spreads its poses evenly over at most slidePoses). The calibration stays on the training poses.
    std::vector<BodyAnchorSlidePose> played;
    nlohmann::json asPlayed;
    if (simulatedFrames) {
      for (const DatasetPose& p : anchorFrameShapes->poses)
        played.push_back({out.model.skeleton.skinningMatrices(p.pose), &p.gameMeshWorld});
      asPlayed = {{"frames", played.size()}, {"simulated", true}};
    } else if (st.anchorsAsPlayed) {
      const AnchorPosesAsPlayed chosen =
          nearestTrainingPoses(theta.leftCols(Eigen::Index(nTrain)), thetaJoints, st.rootGravity, anchorFrames);
      for (uint32_t i : chosen.trainingIndex) played.push_back(training[i]);
      asPlayed = {{"frames", played.size()},
                  {"distinct_training_poses", chosen.distinct},
                  {"theta_distance_median", chosen.medianDistance},
                  {"theta_distance_max", chosen.maxDistance}};
    }
    if (st.anchorsAsPlayed) fitSettings.slidePoses = std::max(fitSettings.slidePoses, played.size());
    BodyAnchorFit fit = fitBodyAnchors(ds.character.body, out.model.skeleton, out.model.gameMesh, fitSettings,
                                       st.anchorsAsPlayed ? played : training);
    out.metadata["body_anchors"] = toJson(fit);
    out.metadata["body_anchors"]["poses_from"] = st.anchorsAsPlayed ? "as_played" : "training";
    if (st.anchorsAsPlayed) out.metadata["body_anchors"]["as_played"] = asPlayed;
    if (st.calibrateAnchors) {
      std::vector<Points3f> predicted(out.trainingPoses.size());
      std::vector<BodyAnchorCalibrationPose> cal(out.trainingPoses.size());
      for (size_t i = 0; i < out.trainingPoses.size(); ++i) {
        const DatasetPose& p = ds.poses[out.trainingPoses[i]];
        predicted[i] = predictPositions(out.model, p.pose, false);
        cal[i] = {training[i].skinMatrices, &p.gameMeshWorld, &predicted[i]};  // the same pose's matrices
      }
      const BodyAnchorCalibration calibration = calibrateBodyAnchors(fit.anchors, cal);
      out.metadata["body_anchors"]["calibration"] = toJson(calibration);
      out.metadata["body_anchors"]["calibration"]["poses_from"] = "the training poses";
    } else {
      out.metadata["body_anchors"]["calibration"] = "none (train.anchor_calibration): every anchor keeps the margin";
    }
    out.model.bodyAnchors = fit.anchors;
    stage("body anchors");
  }

  // The body triangles the garment covers in (nearly) every training pose: what a renderer may leave out.
  if (ds.character.body.triangleCount() > 0) {
    report("body coverage", 0.93);
    std::vector<const DatasetPose*> trained;
    for (uint32_t i : out.trainingPoses) trained.push_back(&ds.poses[i]);
    const BodyCoverageResult cov = coveredBodyTriangles(ds.character, trained);
    out.model.bodyCoverage = {cov.bodyTriangles, cov.covered};
    out.metadata["body_coverage"] = {{"body_triangles", cov.bodyTriangles},
                                     {"covered", cov.covered.size()},
                                     {"min_share_of_poses", BodyCoverageOptions{}.minShare},
                                     {"covered_in_the_first_pose", cov.coveredAtRest},
                                     {"covered_per_pose", cov.perPose},
                                     {"covered_by_share_of_poses", cov.byShare},
                                     {"poses_tested", cov.poses}};
    stage("body coverage");
  }

  std::vector<const DatasetPose*> held;
  for (uint32_t i : out.testPoses) held.push_back(&ds.poses[i]);
  out.evaluation = evaluateModel(out.model, held, out.databaseMaps, maps ? &out.normalPca.pca : nullptr,
                                 ds.character.body.triangleCount() > 0 ? &ds.character.body : nullptr);
  stage("evaluation");

  // The quality ladder on the same held-out poses, through the same path (its full level is the
  // evaluation's total); the CPU times go to the report only. No held-out pose (test fraction 0): the
  // levels stay unmeasured and the model carries none.
  report("quality levels", 0.97);
  out.ladder = runtime::ladderOf(out.model);
  if (!held.empty()) {
    char on[160];
    std::snprintf(on, sizeof on, "the bake's held-out poses (%.0f %% of the dataset, drawn at random, not trained on)",
                  100.0 * st.testFraction);
    out.ladder = measureLadder(out.model, held, out.ladder, on);
    std::vector<const Pose*> heldPoses;
    for (const DatasetPose* p : held) heldPoses.push_back(&p->pose);
    timeLadderCpu(out.model, heldPoses, out.ladder);
  }
  stage("quality levels");

  const auto& ev = out.evaluation;
  out.metadata["errors"] = {
      {"held_out_poses", ev.poses},
      {"vertex_total", toJson(ev.totalMm)},
      {"vertex_pca_truncation", toJson(ev.truncationMm)},
      {"vertex_regression", toJson(ev.regressionMm)},
      {"vertex_baseline_rest_skinned", toJson(ev.restSkinnedMm)},
      {"vertex_baseline_mean_skinned", toJson(ev.meanSkinnedMm)},
      {"mesh_components", K},
      {"mesh_explained_variance", out.meshPca.explainedVariance[K]},
      // No timings here (the report has them): the model's bytes are a function of the recipe alone.
      {"penetration", penetrationJson(ev)},
      {"mlp",
       {{"best_epoch", out.regressor.bestEpoch},
        {"epochs", out.regressor.epochsRun},
        {"validation_loss", out.regressor.bestValidationLoss}}}};
  if (st.distill.poses > 0) {
    std::vector<const DatasetPose*> held;
    for (uint32_t i : out.testPoses) held.push_back(&ds.poses[i]);
    const TeacherComparison c = compareTeacher(out, held);
    const KernelRidgeFit& teacher = out.distilled.teacher;
    out.metadata["distill"] = {{"poses", out.distilled.theta.cols()},
                               {"blends", out.distilled.blends},
                               {"mixes", out.distilled.mixes},
                               {"teacher",
                                {{"kind", "kernel ridge regression, Gaussian kernel, standardised Theta"},
                                 {"width_scale", teacher.widthScale},
                                 {"width", teacher.width},
                                 {"lambda", teacher.lambda},
                                 {"validation_error", teacher.validationError}}},
                               {"held_out_pre_skin_mean_mm", {{"teacher", c.teacherMm}, {"network", c.networkMm}}}};
  }
  if (out.ladder.measured()) out.metadata[runtime::kQualityLevelsKey] = runtime::toJson(withoutTimes(out.ladder));
  if (maps) {
    out.metadata["errors"]["normal_database"] = toJson(ev.normalDatabase);
    out.metadata["errors"]["normal_selection"] = toJson(ev.normalSelection);
    out.metadata["errors"]["normal_total"] = toJson(ev.normalTotal);
    out.metadata["errors"]["normal_vq_added"] = toJson(ev.normalVqAdded);
    out.metadata["errors"]["vq_vs_uncompressed"] = toJson(out.vqVsUncompressed);
    out.metadata["errors"]["bc5_vs_uncompressed"] = toJson(out.bc5VsUncompressed);
    out.metadata["errors"]["bc5_at_vq_memory_vs_uncompressed"] = toJson(out.bc5AtVqMemoryVsUncompressed);
    out.metadata["memory"] = {{"vq_bytes", out.vq.totalBytes()},
                              {"bc5_bytes", out.bc5Bytes},
                              {"database_maps", db.mapCount()},
                              {"codebook_entries", db.codebookSize}};
  }
  out.model.metadata = out.metadata.dump();
  report("done", 1.0);
  return out;
}

}  // namespace swish::bake
