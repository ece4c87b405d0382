#pragma once
// The replay report: report.json (every figure, machine-readable), report.md (for a person: the plan,
// time per stage, GPU-vs-CPU error, ground truth when it ran, per character, bad poses) and
// plots/*.svg (time per frame, error per frame, time per stage, error against time, and with ground
// truth its error per truth frame). Written into `directory` (which the caller stages and renames, so
// nothing partial is left on an error); each file atomically.
//
// Ground truth (--truth-every N) in report.json: "truth" {every, frames, wallSeconds, overall}, per
// character "truth" and per truth frame "truth" [per character]; figures are meanMm/p95Mm/maxMm (per
// vertex, character space) and normalMeanDeg/normalP95Deg/normalMaxDeg (per texel), present only
// where something was measured.
//
// Deterministic apart from times: the same scene and models give the same errors, selections and plan.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_engine.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

nlohmann::json reportJson(const runtime::Scene& scene, const ModelLibrary& models, const ReplayResult& result);
std::string reportMarkdown(const nlohmann::json& report);
void writeReport(const std::filesystem::path& directory, const runtime::Scene& scene, const ModelLibrary& models,
                 const ReplayResult& result);

}  // namespace swish::replay
