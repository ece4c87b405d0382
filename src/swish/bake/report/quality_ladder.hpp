#pragma once
// The quality ladder measured (runtime/quality_levels.hpp defines the levels): for every level of a
// model, the error a character drawn at that level shows against the truth, and what the level costs on
// the CPU. The bake measures it on its held-out poses (part2_training.cpp) and stores it in the model;
// `swish levels` measures it for a model already baked, against the bake's source simulation of clip
// frames.
//
// Error, per level, through the run-time path of the bake's evaluation (bake_evaluation.hpp):
//   Theta -> MLP -> novelty guard (clamp, blend) on all K weights -> the first k weights (the rest 0)
//   -> PCA reconstruction -> skinning (runtime references); k = 0: the PCA mean shape skinned, no network.
//   vertex  distance to the truth's game mesh (character space, posed), mm: mean / p95 / max over every
//           vertex of every pose (the level with k = K is the evaluation's "total", the level k = 0
//           its "mean shape skinned" baseline, bit for bit);
//   normal  the angle between the truth's normal map and what the renderer shades with at that level,
//           degrees, mean over every texel of every pose: with maps, the database map nearest the
//           predicted code, VQ-decoded (the evaluation's "total"); without, the mesh's own normal, i.e.
//           the flat tangent-space map (0, 0, 1). NaN when the poses carry no truth maps.
// CPU time per character (timeLadderCpu): runtime::FrameEvaluator itself, timed on a batch of
// characters all at a level of the kind: Theta + MLP batch + novelty guard when the level needs the
// network, plus the nearest-code lookup and the temporal filter step when it has maps; 0 for the mean
// shape skinned (the evaluator still converts its Theta and measures its novelty for the reports: that
// small share is not counted). The median over repetitions of the batch's time, divided by the
// batch size. The CPU work does not depend on k (the network always predicts every weight): levels of
// the same kind are timed together. GPU time is not measured here (NaN).
//
// The ladder should be monotone: a level that costs no less than a cheaper one (every level costs no
// less than those after it: more components, maps where they have none) should not show a larger error.
// ladderProblems() lists the pairs where it does; nothing is reordered.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/model/model.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish::bake {

// Errors of every level of `ladder` on `poses` (each with its pose, the truth's posed game mesh and,
// when measured, the truth's normal map; gameMeshPreSkin is not read). Returns the ladder with
// vertex*/normalMeanDeg filled in, poses = poses.size() and measuredOn = `measuredOn`; the times are
// left as they were. Throws Error naming the pose when its mesh or map does not fit the model, and when
// there is no pose.
runtime::QualityLadder measureLadder(const Model& model, const std::vector<const DatasetPose*>& poses,
                                     const runtime::QualityLadder& ladder, const std::string& measuredOn);
// The same for the model's own ladder (runtime::ladderOf).
runtime::QualityLadder measureLadder(const Model& model, const std::vector<const DatasetPose*>& poses,
                                     const std::string& measuredOn);

struct LadderTimingOptions {
  uint32_t characters = 22;  // batch size (a football scene)
  uint32_t repeats = 301;    // timed batches per kind of level (median taken)
  uint32_t warmup = 20;      // untimed batches first
};

// Fills in cpuUsPerCharacter of every level and timedOn (cpuDescription() and the MLP kernel), timing
// the run-time CPU path on the poses' network inputs (taken in turn for the batch's characters).
// Throws Error when there is no pose.
void timeLadderCpu(const Model& model, const std::vector<const Pose*>& poses, runtime::QualityLadder& ladder,
                   const LadderTimingOptions& options = {});

// "<model name from /proc/cpuinfo>, 1 thread" (or "unknown CPU, 1 thread" where it cannot be read).
std::string cpuDescription();

// Where the ladder is not monotone, in words: each pair (a level, a cheaper level after it) whose
// vertex mean or normal-map mean error is larger at the dearer level. Empty: monotone (or not measured).
std::vector<std::string> ladderProblems(const runtime::QualityLadder& ladder);

// The ladder with its times removed (cpu/gpu NaN, timedOn empty): what the bake stores in the model,
// whose bytes must be a function of the recipe alone (the cluster bake's model is the local bake's, byte
// for byte); the report carries the times.
runtime::QualityLadder withoutTimes(runtime::QualityLadder ladder);

// The report's forms. `subjects` (optional): the same levels on the held-out subjects (part1.holdout),
// shown beside them. The JSON: toJson(ladder) plus "problems" (and "held_out_subjects": toJson(subjects)
// with its own "problems").
nlohmann::json ladderReportJson(const runtime::QualityLadder& ladder, const runtime::QualityLadder* subjects = nullptr);
// "## Quality levels" with a table per level (k, maps, vertex mean / p95 / max, normal deg, CPU us),
// the problems, and a link to `plotFile` (empty: none).
std::string ladderMarkdown(const runtime::QualityLadder& ladder, const runtime::QualityLadder* subjects,
                           const std::string& plotFile);
// Error against CPU time per character: one point per level (vertex mean, mm), and per level on the
// held-out subjects when given. SVG text (io/svg_plot).
std::string ladderPlotSvg(const runtime::QualityLadder& ladder, const runtime::QualityLadder* subjects = nullptr);

}  // namespace swish::bake
