#pragma once
// The bake report: report.json (every figure), report.md (tables + plots), and beside them
// error_vs_k.svg (PCA truncation RMS and explained variance per K), training_curve.svg (MLP losses),
// and gallery/ (PNG normal maps of the worst held-out poses: baked truth vs what the runtime shows).
// Every file is written atomically.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/part2_training.hpp"
#include "swish/bake/report/subject_evaluation.hpp"

namespace swish::bake {

nlohmann::json bakeReportJson(const BakeTrainOutput& out, const Dataset& dataset);

// Writes the report files into `dir` (created if needed). Returns the path of report.md.
// With `subjects` (part1.holdout), the report shows the held-out subjects beside the random held-out
// frames (subject_evaluation.hpp), in report.md and as report.json's "held_out_subjects".
std::filesystem::path writeBakeReport(const BakeTrainOutput& out, const Dataset& dataset,
                                      const std::filesystem::path& dir, size_t galleryPoses = 4,
                                      const SubjectEvaluation* subjects = nullptr);

}  // namespace swish::bake
