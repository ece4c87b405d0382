#pragma once
// Part 2 of the bake (paper 2.2 from the training data on): Dataset -> mesh PCA, normal-map PCA,
// k-means database, VQ, MLP -> validated Model, plus every measurement the bake report shows.
// Poses are split once (seeded) into a training set and a held-out test set that nothing is fitted on.
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/compression/normal_map_database.hpp"
#include "swish/bake/compression/normal_map_pca.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/report/quality_ladder.hpp"
#include "swish/bake/training/distillation.hpp"
#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct BakeTrainSettings {
  int meshComponents = 24;    // K upper bound
  double meshVariance = 0.0;  // if > 0: smallest K reaching this explained variance (<= meshComponents)
  int normalCodeDims = 8;     // C (0: no normal maps in the model)
  int databaseSize = 128;
  VqOptions vq;
  bool bc5Baseline = true;
  MlpTrainOptions mlp;
  // The normal code's share of the MLP loss against the mesh weights' (1: the two blocks weigh the
  // same). The network is shared, so capacity spent on the code is taken from the mesh.
  double normalCodeWeight = 1.0;
  // The mesh weights' loss weights: (1 - floor) x each component's share of the shape variance + floor
  // / K. 0: the loss is the vertex error (the components are orthonormal), what the evaluation
  // measures; a floor makes the small components count for more. On the default character (1397
  // poses, K = 48, 5x192) a floor of 0.5, the earlier default, gave 3.61 mm held-out against 3.05 mm
  // with 0 (seed 2: 3.39 against 2.94; docs/baking.md).
  double meshWeightFloor = 0.0;
  double testFraction = 0.1;  // held out for the report
  float temporalTimeConstant = 0.1f;
  uint64_t seed = 1;
  // The network's input joints (Theta), by name; empty: the dataset's, the joints part 1 thinned the
  // poses over. The cloth also answers to joints the thinning need not spread poses over: on the
  // default character, adding the forearms and thighs to its 7 thinning joints took the held-out
  // regression error from 4.09 to 3.40 mm (docs/baking.md).
  std::vector<std::string> inputJoints;
  // Theta ends with the gravity direction in the root joint's frame (train.root_gravity, default off):
  // the body's lean against gravity, which no input joint's local rotation holds. Part 1 simulates every
  // pose upright (canonicalPose), so on its datasets the values are constant and trainBake refuses it
  // (docs/baking.md, "What the network cannot see").
  bool rootGravity = false;
  // The push-out's body anchors: calibrated on the training poses so that pushing never takes a
  // vertex further from the simulation there (true, body_anchor_fit.hpp), or every anchor at the margin
  // (false). Where the simulation itself leaves the garment inside the body (the limb clearance's
  // re-skinning puts the arm tubes back through the jersey, docs/baking.md), calibration keeps the
  // push-out from covering the body there, and the body shows through; without it the push-out covers
  // it and moves those vertices away from that truth.
  bool calibrateAnchors = true;
  // The clearance the push-out keeps between the garment and its anchors' balls, in metres
  // (train.anchor_margin_mm; BodyAnchorFitSettings::margin, `swish body-proxy --margin-mm`). Uncalibrated
  // anchors keep it everywhere; on motion the model never saw, a wider margin covers the body where the
  // network's garment dips into it, for a little more error against the truth (docs/baking.md, "The
  // margin, measured").
  float anchorMargin = 0.002f;
  // The third anchor set, the cover anchors (train.cover_anchors; BodyAnchorFitSettings::coverAnchors,
  // `swish body-proxy --no-cover-anchors`): the ball per vertex that covers most of the skin the first
  // two sets leave outside theirs over the training poses (docs/baking.md, "A third set: cover anchors").
  // Off unless the recipe asks (then recorded; absent when off, so that earlier bakes' fingerprints stay):
  // the committed default model was baked before it.
  bool coverAnchors = false;
  // The poses the slide and cover anchors are fitted on (train.anchor_poses). "training", the default: up
  // to 400 of the training poses, spread evenly. Those are the thinned set, spread over the corpus's pose
  // space, so its extremes (arms overhead, deep bends) count as often as the walks and stances a game
  // shows most. "as_played": for each of anchorFramesAsPlayed frames spread evenly over the training
  // clips as a game plays them (one character, unmirrored: the held-out subjects' frames are drawn the
  // same way), the training pose nearest it in the network's Theta, repeats kept, so that each pose
  // weighs as much as the play it stands for. runBake reads those frames from part1.clips and hands
  // them to trainBake (its anchorFrames). Recorded when on; absent when off, so that earlier bakes'
  // fingerprints stay. (docs/baking.md, "Anchors fitted on the frames as played".)
  // With anchorFramesSimulated ({"from": "as_played", "simulated": true}) part 1 simulates those frames
  // themselves (a dataset of their own beside the held-out subjects', resumable as the training poses
  // are; about 10 % more simulation on the default recipe) and the anchors are fitted on their shapes,
  // as `swish body-proxy --clips` fits them (trainBake's anchorFrameShapes).
  bool anchorsAsPlayed = false;
  size_t anchorFramesAsPlayed = 400;
  bool anchorFramesSimulated = false;
  // Distillation (train.distill; distillation.hpp): a kernel-ridge teacher fitted on the training poses
  // labels distill.poses synthetic poses, and the MLP trains on them beside the simulated ones. Off (0
  // poses) unless the recipe asks; recorded when on.
  DistillSettings distill;

  nlohmann::json toJson() const;
};

struct StageTime {
  std::string stage;
  double seconds = 0.0;
};

struct BakeTrainOutput {
  Model model;
  PcaResult meshPca;
  NormalMapPca normalPca;
  DatabaseSelection database;
  std::vector<const NormalMapImage*> databaseMaps;  // uncompressed, pointing into the dataset
  VqReport vq;
  AngularErrorStats vqVsUncompressed, bc5VsUncompressed;
  uint64_t bc5Bytes = 0, uncompressedBytes = 0;
  // BC5 at equal memory: the maps at the largest size whose BC5 fits in the VQ database's bytes
  // (bc5RoundTripResized), sampled back up. 0x0 when no database or no baseline.
  AngularErrorStats bc5AtVqMemoryVsUncompressed;
  uint32_t bc5AtVqMemoryWidth = 0, bc5AtVqMemoryHeight = 0;
  uint64_t bc5AtVqMemoryBytes = 0;
  MlpTrainResult regressor;
  DistilledSamples distilled;  // train.distill's teacher and samples (none when off)
  BakeEvaluation evaluation;
  // The model's quality levels (runtime/quality_levels.hpp) measured on the same held-out poses as
  // `evaluation` (its full level is evaluation.totalMm), with CPU times; the model's metadata carries
  // them without the times (quality_ladder.hpp, withoutTimes: the model's bytes stay a function of the
  // recipe), the report with them.
  runtime::QualityLadder ladder;
  std::vector<uint32_t> trainingPoses, testPoses;  // indices into dataset.poses
  std::vector<uint32_t> pinnedPoses;  // indices into dataset.poses always trained on (the rest pose part 1 added)
  size_t synthesizedPoses = 0;        // part1.synthesis's poses: trained on, never held out
  std::vector<StageTime> stages;
  nlohmann::json metadata;  // what went into Model::metadata
};

// Progress: (stage, fraction of part 2 done in [0, 1]).
using BakeProgress = std::function<void(const std::string& stage, double fraction)>;

// The dataset must outlive the output (databaseMaps points into it). Throws Error for datasets it
// cannot train on (fewer than 3 poses, mismatched mesh sizes, maps of mixed sizes, ...).
// The skeleton indices of the network's input joints: settings.inputJoints resolved on the dataset's
// character (throws Error naming a joint it lacks, or one named twice), or the dataset's.
std::vector<uint32_t> networkInputJoints(const Dataset& ds, const BakeTrainSettings& settings);

// train.distill's teacher against the network on poses (mean pre-skinning vertex distance through the mesh
// PCA, mm): whether the teacher was worth learning from. Zeros when the bake did not distil or no poses.
struct TeacherComparison {
  size_t poses = 0;
  double teacherMm = 0.0, networkMm = 0.0;
};
TeacherComparison compareTeacher(const BakeTrainOutput& out, const std::vector<const DatasetPose*>& poses);

// `anchorFrames`: with settings.anchorsAsPlayed, the frames as played that choose the anchors' poses
// (above); `anchorFrameShapes`: with anchorFramesSimulated too, those frames simulated (a dataset on the
// same character), whose poses and shapes the anchors are fitted on instead (anchorFrames is then not
// needed). Error when the setting is on and what it needs is not given, or when they are given with it off.
BakeTrainOutput trainBake(const Dataset& dataset, const BakeTrainSettings& settings, const BakeProgress& progress = {},
                          std::span<const Pose> anchorFrames = {}, const Dataset* anchorFrameShapes = nullptr);

}  // namespace swish::bake
