#pragma once
// The honest figure: the model on whole subjects it never trained on (part1.holdout), beside the usual
// figure on random held-out frames of its training clips. The held-out subjects' frames are simulated
// into their own dataset (BakeConfig::holdoutDatasetDir, evenly spaced over their clips); here each is
// evaluated through the same run-time path as the bake's own held-out poses (bake_evaluation.hpp):
// vertex error mean / p95 / max and normal-map angular error, with both baselines (the rest shape
// skinned, the PCA mean shape skinned) on the same poses, overall and per held-out clip; overall also
// the garment inside the character's body (truth, model, model after the run-time push-out) and the
// error with the push-out, where the dataset has the body.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/part2_training.hpp"

namespace swish::bake {

// A study of the run-time novelty guard (runtime/novelty_guard.hpp) on the bake's own poses: each
// pose's novelty as the run time measures it with the model's guard (distance of the normalised network
// input to the nearest k-means centre of the training inputs, over the guard's unit), and the error under
// each setting: no guard, the clamp of the mesh weights to the training shapes' range, and the clamp
// with a blend towards 0 (the PCA mean shape, the better of the two baselines) as novelty goes from
// `start` to `end`. The chosen row (lowest mean on the held-out subjects) goes into the model
// (bake_pipeline.cpp). The model must carry a fitted guard (trainBake fits one); else the study is empty.
struct GuardSetting {
  bool clamp = false;
  double start = 0.0, end = 0.0;  // end > start: blend; else none
  std::string name() const;
};
struct GuardStudy {
  double unit = 0.0;                             // the guard's unit (RMS per input)
  DistanceStats noveltySubjects, noveltyRandom;  // of the novelty values (no unit)
  double errorNoveltyCorrelation = 0.0;          // held-out subjects: per-pose mean error vs novelty (Pearson)
  struct Row {
    GuardSetting setting;
    DistanceStats subjects, random;  // vertex error (mm)
  };
  std::vector<Row> rows;  // [0]: no guard, [1]: clamp only, then clamp + blend settings
  size_t chosen = 0;      // the row with the lowest mean on the held-out subjects
  nlohmann::json toJson() const;
  std::string markdown() const;
};

// `trainingPoses` trained the model; the guard is measured on both other sets.
GuardStudy studyNoveltyGuard(const Model& model, const std::vector<const DatasetPose*>& trainingPoses,
                             const std::vector<const DatasetPose*>& heldOutSubjects,
                             const std::vector<const DatasetPose*>& randomFrames);

struct SubjectEvaluation {
  std::vector<std::string> subjects;
  size_t posesPlanned = 0;  // frames part 1 was asked to simulate; the dataset holds those that succeeded
  BakeEvaluation overall;
  struct Clip {
    std::string clip, subject;
    BakeEvaluation evaluation;
  };
  std::vector<Clip> perClip;
  // Per held-out subject, how much of the error is the same in every one of its frames: the mean over
  // its poses of the per-vertex error vector, in pre-skinning space (where a garment that sits
  // differently on this subject's posture is the same offset whatever the limbs do), against the mean
  // error there. A large share says the corpus lacks this subject's way of standing (or the truth sits
  // it in another fold), not its motion; |mean of the errors| <= mean of |errors| bounds it.
  struct Subject {
    std::string subject;
    size_t poses = 0;
    double errorMm = 0.0;       // mean over poses and vertices of |predicted - truth|, pre-skinning space
    double systematicMm = 0.0;  // mean over vertices of |mean over poses of (predicted - truth)|
    // The same two figures over the game vertices of each skinning joint (a vertex goes with its
    // strongest joint): where on the garment the offset sits (a collar on the neck's posture, a hem on
    // the hips', sleeves on the arms'). Joints in skeleton order, those with no vertex left out.
    struct Region {
      std::string joint;
      size_t vertices = 0;
      double errorMm = 0.0, systematicMm = 0.0;
    };
    std::vector<Region> byJoint;
  };
  std::vector<Subject> perSubject;
  GuardStudy guard;
  // The model's quality levels (the random held-out frames' ladder, BakeTrainOutput::ladder) on the
  // held-out subjects' frames: errors only (the times are the same work, in the ladder).
  runtime::QualityLadder levels;

  // {"subjects", "poses", "overall": {...}, "per_clip": [{"clip", "subject", ...}]}, each evaluation as
  // {"poses", "vertex": {mean_mm, p95_mm, max_mm}, "baseline_rest_skinned", "baseline_mean_skinned",
  //  "normal_total": {mean_deg, ...}}, "penetration" (penetrationJson of `overall`, when measured), and
  //  "quality_levels" (the levels on the subjects, without times):
  // what the report and the model metadata carry.
  nlohmann::json toJson() const;
  // The report's section: the held-out subjects against `randomFrames` (the bake's random held-out
  // frames of training clips) side by side, then per clip.
  std::string markdown(const BakeEvaluation& randomFrames) const;
};

// The compact JSON form of one evaluation (as in SubjectEvaluation::toJson).
nlohmann::json evaluationSummary(const BakeEvaluation& ev);

// `holdout` is the held-out subjects' dataset, `origins` its pose_origins.json (per pose id: clip,
// subject). Throws Error when the dataset does not fit the model (another game mesh) or is empty.
// `training` is the dataset the model was trained on (out.trainingPoses and out.testPoses index it).
SubjectEvaluation evaluateHeldOutSubjects(const BakeTrainOutput& out, const Dataset& training, const Dataset& holdout,
                                          const nlohmann::json& origins, const std::vector<std::string>& subjects,
                                          size_t posesPlanned);

}  // namespace swish::bake
