#include "swish/replay/report_writer.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>
#include <vector>

#include "swish/files/atomic_write.hpp"
#include "swish/io/svg_plot.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/scene_file.hpp"

namespace swish::replay {

namespace {

using nlohmann::json;

struct StageColumn {
  const char* key;
  const char* label;
  double FrameTimes::*field;
};
const std::vector<StageColumn>& stageColumns() {
  static const std::vector<StageColumn> s = {
      {"pose", "CPU pose + FK + skin matrices", &FrameTimes::pose},
      {"theta", "CPU Theta (6D)", &FrameTimes::theta},
      {"mlp", "CPU MLP", &FrameTimes::mlp},
      {"novelty", "CPU novelty guard", &FrameTimes::novelty},
      {"lookup", "CPU lookup + filter", &FrameTimes::lookup},
      {"record", "CPU record + upload", &FrameTimes::record},
      {"gpuDeform", "GPU deform", &FrameTimes::gpuDeform},
      {"gpuTangents", "GPU normals + tangents", &FrameTimes::gpuTangents},
      {"gpuDecode", "GPU VQ decode", &FrameTimes::gpuDecode},
      {"gpuBlend", "GPU normal-map blend", &FrameTimes::gpuBlend},
      {"gpuTotal", "GPU total (timestamps)", &FrameTimes::gpuTotal},
      {"gpuWait", "submit to fence (wall)", &FrameTimes::gpuWait},
  };
  return s;
}

double quantile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[size_t(std::min<double>(double(v.size() - 1), std::floor(q * double(v.size()))))];
}

std::string fmt(double v, const char* f = "%.4g") {
  if (!std::isfinite(v)) return "-";
  char s[48];
  std::snprintf(s, sizeof s, f, v);
  return s;
}
double num(const json& j) { return j.is_number() ? j.get<double>() : NAN; }
double finiteMean(const std::vector<double>& v) {
  double sum = 0;
  size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) sum += x, ++n;
  return n ? sum / double(n) : NAN;
}

// Pooled ground truth; figures only where something was measured (null would read as zero error).
json truthJson(const TruthSummary& t) {
  json j{{"samples", t.samples}, {"failed", t.failed}, {"seconds", t.seconds}, {"cpuSeconds", t.cpuSeconds}};
  if (t.samples > 0) {
    j["meanMm"] = t.meanMm, j["p95Mm"] = t.p95Mm, j["maxMm"] = t.maxMm;
    if (t.comparedWithout)
      j["withoutPushOut"] = {{"meanMm", t.meanMmWithout}, {"p95Mm", t.p95MmWithout}, {"maxMm", t.maxMmWithout}};
    if (t.comparedWithout && t.splitByTruth)
      j["withoutPushOut"]["byTruth"] = {
          {"truthInsideShare", t.truthInsideShare},
          {"truthOutside", {{"meanMm", t.meanMmTruthOutside}, {"meanMmWithout", t.meanMmWithoutTruthOutside}}},
          {"truthInside", {{"meanMm", t.meanMmTruthInside}, {"meanMmWithout", t.meanMmWithoutTruthInside}}}};
    if (t.normalMaps) j["normalMeanDeg"] = t.meanDeg, j["normalP95Deg"] = t.p95Deg, j["normalMaxDeg"] = t.maxDeg;
  }
  return j;
}

json poolJson(const bake::PenetrationPool& p) {
  return {{"frames", p.frames},
          {"framesWithInside", p.framesInside},
          {"framesVisible", p.framesVisible},
          {"vertices", p.vertices},
          {"inside", p.inside},
          {"visible", p.visible},
          {"share", p.share()},
          {"deepestMm", p.deepestMm},
          {"deepestP95Mm", p.deepestPercentileMm(0.95)}};
}

json penetrationJson(const PenetrationSummary& s) {
  json j{{"model", poolJson(s.model)}};
  if (s.pushedMeasured) j["pushed"] = poolJson(s.pushed);
  return j;
}

json statsJson(const bake::PenetrationStats& s) {
  return {{"inside", s.inside}, {"visible", s.visible}, {"share", s.share()}, {"deepestMm", s.deepestMm}};
}

// Mean over a frame's measured characters of their mean vertex error, and the worst max; NaN if none.
std::pair<double, double> frameTruthMm(const FrameRecord& f) {
  double sum = 0, worst = 0;
  int n = 0;
  for (const auto& c : f.truth)
    if (c.ok) sum += c.meanMm, worst = std::max(worst, c.maxMm), ++n;
  return n ? std::make_pair(sum / n, worst) : std::make_pair(double(NAN), double(NAN));
}

}  // namespace

json reportJson(const runtime::Scene& scene, const ModelLibrary& models, const ReplayResult& r) {
  json j;
  j["swishReplayReport"] = 1;
  j["scene"] = runtime::sceneToJson(scene);
  j["device"] = r.device;
  j["models"] = json::array();
  for (const auto& e : models.entries()) {
    const Model& m = e->model;
    j["models"].push_back({{"key", e->key},
                           {"label", e->label},
                           {"procedural", e->procedural},
                           {"vertices", m.gameMesh.vertexCount()},
                           {"triangles", m.gameMesh.triangleCount()},
                           {"joints", m.skeleton.size()},
                           {"inputJoints", m.inputJoints.size()},
                           {"meshComponents", m.meshComponents()},
                           {"normalMaps", m.normalMaps.mapCount()},
                           {"mapSize", m.normalMaps.width}});
    // The bake measures the model on its held-out poses through the runtime path (metadata "errors",
    // see part2_training.cpp): the ground-truth error of this model, quoted beside the run times.
    const json meta = json::parse(m.metadata, nullptr, false);
    if (!meta.is_discarded() && meta.is_object() && meta.contains("errors") && meta["errors"].is_object())
      j["models"].back()["heldOutErrors"] = meta["errors"];
  }
  j["plan"] = r.plan.toJson();
  j["truth"] = {{"available", r.truthAvailable}, {"note", r.truthNote}, {"every", r.truthEvery}};
  if (r.truthEvery > 0) {
    j["truth"]["frames"] = r.truthFrames;
    j["truth"]["wallSeconds"] = r.truthWallSeconds;
    j["truth"]["overall"] = truthJson(r.truthOverall);
  }
  j["penetration"] = {{"every", r.penetrationEvery},
                      {"note", r.penetrationNote},
                      {"pushOut", r.pushOut},
                      {"visibleDepthMm", bake::kVisiblePenetrationMm},
                      {"seconds", r.penetrationSeconds}};
  if (!r.penetrationPerCharacter.empty()) j["penetration"]["overall"] = penetrationJson(r.penetrationOverall);
  j["frames"] = json::array();
  std::vector<json> perChar(scene.characters.size());
  for (size_t c = 0; c < scene.characters.size(); ++c)
    perChar[c] = {{"name", scene.characters[c].name},
                  {"model", scene.characters[c].model},
                  {"onScreen", scene.onScreen(c)},
                  {"checks", 0},
                  {"maxPositionErrorMm", 0.0},
                  {"maxNormalErrorDeg", 0.0},
                  {"maxMapErrorSteps", 0},
                  {"poseIssues", 0}};
  for (const auto& f : r.frames) {
    json t;
    for (const auto& s : stageColumns()) t[s.key] = f.times.*s.field;
    t["cpuTotal"] = f.times.cpuTotal();
    json fj{{"frame", f.frame},
            {"times", t},
            {"gpuDispatches", f.gpuDispatches},
            {"checked", f.checked},
            {"poseIssues", f.poseIssues}};
    if (f.truthFrame) {
      fj["truth"] = json::array();
      for (const auto& c : f.truth) {
        json t{{"character", scene.characters[c.character].name},
               {"ok", c.ok},
               {"seconds", c.seconds},
               {"cpuSeconds", c.cpuSeconds},
               {"limbCorrections", c.limbCorrections}};
        if (c.ok) {
          t["meanMm"] = c.meanMm, t["p95Mm"] = c.p95Mm, t["maxMm"] = c.maxMm;
          if (c.comparedWithout)
            t["withoutPushOut"] = {{"meanMm", c.meanMmWithout}, {"p95Mm", c.p95MmWithout}, {"maxMm", c.maxMmWithout}};
          if (c.normalMap) t["normalMeanDeg"] = c.meanDeg, t["normalP95Deg"] = c.p95Deg, t["normalMaxDeg"] = c.maxDeg;
        } else {
          t["failure"] = c.failure;
        }
        fj["truth"].push_back(t);
      }
    }
    if (!f.penetration.empty()) {
      fj["penetration"] = json::array();
      for (const auto& p : f.penetration) {
        json pj{{"character", scene.characters[p.character].name}, {"model", statsJson(p.model)}};
        if (p.pushedMeasured) pj["pushed"] = statsJson(p.pushed);
        fj["penetration"].push_back(pj);
      }
    }
    if (!f.novelty.empty()) {
      fj["novelty"] = json::array();
      for (const auto& nv : f.novelty)
        fj["novelty"].push_back({{"character", scene.characters[nv.character].name},
                                 {"novelty", nv.novelty},
                                 {"blend", nv.blend},
                                 {"flagged", nv.flagged}});
    }
    if (!f.levels.empty()) {
      fj["levels"] = f.levels;
      fj["levelChanges"] = f.levelChanges;
      fj["predictedGpuMs"] = f.predictedGpuMs;
      fj["costScale"] = f.costScale;
      fj["weightedErrorMm"] = f.weightedErrorMm;
    }
    if (f.checked)
      fj["gpuVsCpu"] = {{"maxPositionErrorMm", f.maxPositionErrorMm()},
                        {"maxNormalErrorDeg", f.maxNormalErrorDeg()},
                        {"maxMapErrorSteps", f.maxMapErrorSteps()}};
    for (const auto& c : f.checks) {
      json& pc = perChar[c.character];
      pc["checks"] = pc["checks"].get<int>() + 1;
      pc["maxPositionErrorMm"] = std::max(pc["maxPositionErrorMm"].get<double>(), c.maxPositionErrorMm);
      pc["maxNormalErrorDeg"] =
          std::max({pc["maxNormalErrorDeg"].get<double>(), c.maxNormalErrorDeg, c.maxTangentErrorDeg});
      pc["maxMapErrorSteps"] = std::max(pc["maxMapErrorSteps"].get<int>(), c.maxMapErrorSteps);
    }
    j["frames"].push_back(fj);
  }
  for (const auto& i : r.issues)
    for (size_t c = 0; c < scene.characters.size(); ++c)
      if (scene.characters[c].name == i.character) perChar[c]["poseIssues"] = perChar[c]["poseIssues"].get<int>() + 1;
  for (size_t c = 0; c < r.truthPerCharacter.size() && c < perChar.size(); ++c)
    perChar[c]["truth"] = truthJson(r.truthPerCharacter[c]);
  for (size_t c = 0; c < r.penetrationPerCharacter.size() && c < perChar.size(); ++c)
    if (r.penetrationPerCharacter[c].model.frames > 0)
      perChar[c]["penetration"] = penetrationJson(r.penetrationPerCharacter[c]);
  // Novelty per character over the replay, and the flagged frames (the first kMaxFlagged of them).
  {
    constexpr size_t kMaxFlagged = 200;
    std::vector<std::vector<double>> perCharNovelty(scene.characters.size());
    std::vector<size_t> flaggedPerChar(scene.characters.size(), 0);
    json flagged = json::array();
    size_t flaggedCount = 0, measured = 0;
    std::vector<double> all;
    for (const auto& f : r.frames)
      for (const auto& nv : f.novelty) {
        perCharNovelty[nv.character].push_back(nv.novelty);
        all.push_back(nv.novelty);
        ++measured;
        if (!nv.flagged) continue;
        ++flaggedPerChar[nv.character];
        if (flaggedCount++ < kMaxFlagged)
          flagged.push_back({{"frame", f.frame},
                             {"character", scene.characters[nv.character].name},
                             {"novelty", nv.novelty},
                             {"blend", nv.blend}});
      }
    j["novelty"] = {{"measured", measured > 0},
                    {"guard", r.noveltyGuard},
                    {"characterFrames", measured},
                    {"flaggedCharacterFrames", flaggedCount},
                    {"flagged", flagged}};
    if (measured > 0)
      j["novelty"]["overall"] = {{"mean", std::accumulate(all.begin(), all.end(), 0.0) / double(all.size())},
                                 {"p95", quantile(all, 0.95)},
                                 {"max", *std::max_element(all.begin(), all.end())}};
    for (size_t c = 0; c < perChar.size(); ++c) {
      const auto& v = perCharNovelty[c];
      if (v.empty()) continue;
      perChar[c]["novelty"] = {{"mean", std::accumulate(v.begin(), v.end(), 0.0) / double(v.size())},
                               {"p95", quantile(v, 0.95)},
                               {"max", *std::max_element(v.begin(), v.end())},
                               {"framesFlagged", flaggedPerChar[c]}};
    }
  }
  // Quality levels: each model's ladder (with the calibrated cost and the truth per level), each
  // character's levels over the replay, and the budget against the measured GPU time.
  {
    json lv = {{"frameBudgetMs", r.frameBudgetMs ? json(*r.frameBudgetMs) : json(nullptr)},
               {"tolerancePixels", r.tolerancePixels ? json(*r.tolerancePixels) : json(nullptr)},
               {"holdFrames", r.levelHoldFrames},
               {"costs", r.levelCostsSource},
               {"models", json::array()},
               {"characters", json::array()}};
    for (const ModelLevels& m : r.levels) {
      json mj{{"model", m.model}, {"ladder", runtime::toJson(m.ladder)}};
      if (!m.calibratedMsPerCharacter.empty()) mj["calibratedMsPerCharacter"] = m.calibratedMsPerCharacter;
      if (!m.truth.empty()) {
        mj["truth"] = json::array();
        for (size_t l = 0; l < m.truth.size(); ++l)
          mj["truth"].push_back({{"level", m.ladder[l].name},
                                 {"vertexDistances", m.truth[l].samples},
                                 {"meanMm", m.truth[l].meanMm},
                                 {"p95Mm", m.truth[l].p95Mm},
                                 {"maxMm", m.truth[l].maxMm}});
      }
      lv["models"].push_back(mj);
    }
    const size_t window = size_t(std::max(1.0, std::round(scene.framesPerSecond)));
    for (size_t s = 0; s < r.levelCharacters.size(); ++s) {
      const uint32_t c = r.levelCharacters[s];
      std::map<int, uint32_t> counts;
      std::vector<size_t> changeFrames;
      for (size_t f = 0; f < r.frames.size(); ++f) {
        if (s >= r.frames[f].levels.size()) continue;
        ++counts[r.frames[f].levels[s]];
        if (f > 0 && s < r.frames[f - 1].levels.size() && r.frames[f].levels[s] != r.frames[f - 1].levels[s])
          changeFrames.push_back(f);
      }
      size_t worst = 0;  // most changes within any one second of frames
      for (size_t a = 0; a < changeFrames.size(); ++a) {
        size_t b = a;
        while (b < changeFrames.size() && changeFrames[b] < changeFrames[a] + window) ++b;
        worst = std::max(worst, b - a);
      }
      json cj{{"name", scene.characters[c].name},
              {"firstReason", s < r.levelReasons.size() ? r.levelReasons[s] : std::string()},
              {"changes", changeFrames.size()},
              {"maxChangesPerSecond", worst},
              {"framesPerLevel", json::object()}};
      for (const auto& [l, n] : counts) cj["framesPerLevel"][std::to_string(l)] = n;
      lv["characters"].push_back(cj);
    }
    std::vector<double> predicted, measured, weighted, full, scales;
    size_t over = 0;
    for (const auto& f : r.frames) {
      if (f.levels.empty()) continue;
      predicted.push_back(f.predictedGpuMs);
      measured.push_back(f.times.gpuTotal);
      weighted.push_back(f.weightedErrorMm);
      full.push_back(f.fullErrorMm);
      scales.push_back(f.costScale);
      if (r.frameBudgetMs && std::isfinite(f.times.gpuTotal) && f.times.gpuTotal > *r.frameBudgetMs) ++over;
    }
    lv["summary"] = {{"medianPredictedGpuMs", quantile(predicted, 0.5)},
                     {"medianGpuMs", quantile(measured, 0.5)},
                     {"framesOverBudget", over},
                     {"medianCostScale", quantile(scales, 0.5)},
                     {"meanWeightedErrorMm", finiteMean(weighted)},
                     {"meanFullErrorMm", finiteMean(full)}};
    j["levels"] = lv;
  }
  j["characters"] = perChar;
  json summary;
  for (const auto& s : stageColumns()) {
    std::vector<double> v;
    for (const auto& f : r.frames) v.push_back(f.times.*s.field);
    summary["medianMs"][s.key] = quantile(v, 0.5);
    summary["p95Ms"][s.key] = quantile(v, 0.95);
  }
  std::vector<double> cpu;
  for (const auto& f : r.frames) cpu.push_back(f.times.cpuTotal());
  summary["medianMs"]["cpuTotal"] = quantile(cpu, 0.5);
  double maxPos = 0, maxDeg = 0;
  int maxMap = 0, checked = 0;
  for (const auto& f : r.frames)
    if (f.checked) {
      ++checked;
      maxPos = std::max(maxPos, f.maxPositionErrorMm());
      maxDeg = std::max(maxDeg, f.maxNormalErrorDeg());
      maxMap = std::max(maxMap, f.maxMapErrorSteps());
    }
  summary["frames"] = r.frames.size();
  summary["checkedFrames"] = checked;
  summary["gpuVsCpu"] = {{"maxPositionErrorMm", maxPos}, {"maxNormalErrorDeg", maxDeg}, {"maxMapErrorSteps", maxMap}};
  summary["failures"] = r.failures.size();
  summary["poseIssues"] = r.issueCount;
  summary["failed"] = r.failed();
  j["summary"] = summary;
  j["failures"] = r.failures;
  j["issues"] = json::array();
  for (const auto& i : r.issues)
    j["issues"].push_back({{"frame", i.frame},
                           {"character", i.character},
                           {"joint", i.joint},
                           {"problem", i.problem},
                           {"action", i.action}});
  return j;
}

std::string reportMarkdown(const json& j) {
  std::ostringstream s;
  const json& sum = j["summary"];
  s << "# swish replay: " << j["scene"]["name"].get<std::string>() << "\n\n";
  s << "**Result: " << (sum["failed"].get<bool>() ? "FAILED" : "OK") << "** -- " << sum["frames"] << " frames, "
    << j["characters"].size() << " characters, device: " << j["device"].get<std::string>() << ".\n\n";
  s << "## Models\n\n";
  for (const auto& m : j["models"])
    s << "- `" << m["key"].get<std::string>() << "`: " << m["label"].get<std::string>() << " -- " << m["vertices"]
      << " vertices, " << m["joints"] << " joints (" << m["inputJoints"] << " in Theta), K = " << m["meshComponents"]
      << ", " << m["normalMaps"] << " normal maps of " << m["mapSize"] << " px\n";
  for (const auto& m : j["models"]) {
    if (!m.contains("heldOutErrors")) continue;
    const json& e = m["heldOutErrors"];
    s << "  - ground truth from the bake (" << e.value("held_out_poses", 0)
      << " held-out poses, simulated): vertex error";
    if (e.contains("vertex_total"))
      s << " mean " << fmt(num(e["vertex_total"]["mean_mm"])) << " mm, p95 " << fmt(num(e["vertex_total"]["p95_mm"]))
        << " mm, max " << fmt(num(e["vertex_total"]["max_mm"])) << " mm";
    if (e.contains("normal_total"))
      s << "; normal-map angular error mean " << fmt(num(e["normal_total"]["mean_deg"])) << " deg, p95 "
        << fmt(num(e["normal_total"]["p95_deg"])) << " deg";
    s << "\n";
  }
  int fewest = INT_MAX, most = 0;  // dispatches recorded per frame (the VQ decode only for new maps)
  for (const auto& f : j["frames"])
    fewest = std::min(fewest, f["gpuDispatches"].get<int>()), most = std::max(most, f["gpuDispatches"].get<int>());
  s << "\n## Plan\n\nAt most " << j["plan"]["gpuDispatchesPerFrame"] << " GPU dispatches per frame (recorded: "
    << (j["frames"].empty() ? std::string("no frames") : std::to_string(fewest) + " to " + std::to_string(most))
    << "), " << fmt(num(j["plan"]["gpuBytes"]) / 1048576.0, "%.2f") << " MiB of GPU memory, "
    << j["plan"]["rot6JointsPerFrame"] << " joints converted to 6D per frame.\n\nLeft out:\n\n";
  for (const auto& l : j["plan"]["leftOut"])
    s << "- " << l["what"].get<std::string>() << " -- because " << l["why"].get<std::string>() << "\n";
  if (j["plan"]["leftOut"].empty()) s << "- nothing\n";
  s << "\n## Error against run time\n\n";
  s << "Ground truth: " << (j["truth"]["available"].get<bool>() ? "available" : "not available") << " -- "
    << j["truth"]["note"].get<std::string>() << ".\n\n";
  if (j["truth"].contains("overall")) {
    const json& t = j["truth"]["overall"];
    const double poses = num(t["samples"]) + num(t["failed"]);
    const double frames = num(j["truth"]["frames"]);
    s << "Ground truth every " << j["truth"]["every"] << " frames: " << t["samples"]
      << " character poses simulated and measured on " << j["truth"]["frames"] << " frames, " << t["failed"]
      << " more whose simulation failed (the bake leaves such poses out too); "
      << fmt(poses > 0 ? num(t["cpuSeconds"]) / poses : NAN, "%.2f") << " s CPU per pose ("
      << fmt(poses > 0 ? num(t["seconds"]) / poses : NAN, "%.2f") << " s wall on its thread), "
      << fmt(num(j["truth"]["wallSeconds"]), "%.1f") << " s wall in all ("
      << fmt(frames > 0 ? num(j["truth"]["wallSeconds"]) / frames : NAN, "%.1f")
      << " s per truth frame), outside the timed stages below.\n\n";
    if (t.contains("meanMm")) {
      s << "Run time against ground truth, character space (placement excluded): vertex error mean "
        << fmt(num(t["meanMm"])) << " mm, p95 " << fmt(num(t["p95Mm"])) << " mm, max " << fmt(num(t["maxMm"])) << " mm";
      if (t.contains("normalMeanDeg"))
        s << "; normal-map angular error mean " << fmt(num(t["normalMeanDeg"])) << " deg, p95 "
          << fmt(num(t["normalP95Deg"])) << " deg, max " << fmt(num(t["normalMaxDeg"])) << " deg";
      s << ".\n\n";
      if (t.contains("withoutPushOut")) {
        const json& w = t["withoutPushOut"];
        s << "The same truth frames without the push-out (the CPU reference's positions): vertex error mean "
          << fmt(num(w["meanMm"])) << " mm, p95 " << fmt(num(w["p95Mm"])) << " mm, max " << fmt(num(w["maxMm"]))
          << " mm: the push-out changes the mean by " << fmt(num(t["meanMm"]) - num(w["meanMm"]), "%+.3f")
          << " mm and the p95 by " << fmt(num(t["p95Mm"]) - num(w["p95Mm"]), "%+.3f") << " mm.";
        if (w.contains("byTruth")) {
          const json& b = w["byTruth"];
          const json &out = b["truthOutside"], &in = b["truthInside"];
          s << " Split by where the truth lies: where it is outside the body ("
            << fmt(100.0 * (1.0 - num(b["truthInsideShare"])), "%.1f") << " % of the vertices) the mean goes from "
            << fmt(num(out["meanMmWithout"])) << " to " << fmt(num(out["meanMm"])) << " mm ("
            << fmt(num(out["meanMm"]) - num(out["meanMmWithout"]), "%+.3f")
            << "); where the truth itself is inside the body (" << fmt(100.0 * num(b["truthInsideShare"]), "%.1f")
            << " %: the source simulation's cloth inside an arm or the trunk, which a garment kept off the body "
               "cannot match) from "
            << fmt(num(in["meanMmWithout"])) << " to " << fmt(num(in["meanMm"])) << " mm ("
            << fmt(num(in["meanMm"]) - num(in["meanMmWithout"]), "%+.3f") << ").";
        }
        s << "\n\n";
      }
      s << "![error against ground truth per truth frame](plots/truth_error_per_frame.svg)\n\n";
    }
  }
  if (j.contains("levels") && !j["levels"]["models"].empty()) {
    const json& lv = j["levels"];
    s << "## Quality levels\n\n";
    s << "Each character runs at a level of its model's ladder (full quality down to the mean shape skinned), "
         "chosen per frame by the level planner from its size on screen"
      << (lv["frameBudgetMs"].is_number() ? " and the frame budget of " + fmt(num(lv["frameBudgetMs"])) + " GPU ms"
                                          : std::string(" (no frame budget)"))
      << (lv["tolerancePixels"].is_number()
              ? ", at the cheapest level within " + fmt(num(lv["tolerancePixels"])) + " px of error on screen"
              : std::string(""))
      << "; a character keeps a level at least " << lv["holdFrames"]
      << " frames. Costs: " << lv["costs"].get<std::string>() << ".\n\n";
    for (const auto& m : lv["models"]) {
      const json& ladder = m["ladder"];
      s << "Model `" << m["model"].get<std::string>() << "`: errors measured on "
        << (ladder["poses"].get<uint32_t>() > 0 ? ladder["measured_on"].get<std::string>()
                                                : std::string("nothing (the model's ladder is not measured)"))
        << ".\n\n| level | components | normal maps | vertex mean / p95 mm (ladder) | normal deg | CPU us per "
           "character | GPU ms per character (calibrated) | vertex mean / p95 mm against truth here |\n"
           "|---|---:|---|---:|---:|---:|---:|---:|\n";
      for (size_t l = 0; l < ladder["levels"].size(); ++l) {
        const json& e = ladder["levels"][l];
        s << "| " << l << " " << e["name"].get<std::string>() << " | " << e["mesh_components"] << " | "
          << (e["normal_maps"].get<bool>() ? "yes" : "no") << " | " << fmt(num(e["vertex_mean_mm"]), "%.2f") << " / "
          << fmt(num(e["vertex_p95_mm"]), "%.2f") << " | " << fmt(num(e["normal_mean_deg"]), "%.2f") << " | "
          << fmt(num(e["cpu_us_per_character"]), "%.1f") << " | "
          << (m.contains("calibratedMsPerCharacter") ? fmt(num(m["calibratedMsPerCharacter"][l]), "%.3f") : "-")
          << " | "
          << (m.contains("truth") && l < m["truth"].size()
                  ? fmt(num(m["truth"][l]["meanMm"]), "%.2f") + " / " + fmt(num(m["truth"][l]["p95Mm"]), "%.2f")
                  : std::string("-"))
          << " |\n";
      }
      s << "\n";
    }
    const json& sm = lv["summary"];
    s << "Per frame (medians): predicted GPU " << fmt(num(sm["medianPredictedGpuMs"]), "%.3f") << " ms, measured GPU "
      << fmt(num(sm["medianGpuMs"]), "%.3f") << " ms";
    if (lv["frameBudgetMs"].is_number())
      s << "; " << sm["framesOverBudget"] << " frames measured over the budget of " << fmt(num(lv["frameBudgetMs"]))
        << " ms";
    s << ". Screen-weighted ladder error of the chosen levels " << fmt(num(sm["meanWeightedErrorMm"]), "%.2f")
      << " mm against " << fmt(num(sm["meanFullErrorMm"]), "%.2f")
      << " mm at full quality (mean over frames; the weight is each character's projected area).\n\n"
      << "![levels per frame](plots/levels_per_frame.svg)\n\n"
      << "| character | level on the first frame, and why | frames per level | changes | most changes in one "
         "second |\n|---|---|---|---:|---:|\n";
    for (const auto& c : lv["characters"]) {
      std::string per;
      for (const auto& [l, n] : c["framesPerLevel"].items()) per += (per.empty() ? "" : ", ") + l + ": " + n.dump();
      s << "| " << c["name"].get<std::string>() << " | " << c["firstReason"].get<std::string>() << " | " << per << " | "
        << c["changes"] << " | " << c["maxChangesPerSecond"] << " |\n";
    }
    s << "\n";
  }
  {
    const json& nv = j["novelty"];
    s << "## Novelty: poses the model never saw\n\n";
    if (!nv["measured"].get<bool>()) {
      s << "Not measured: no model in the scene carries a novelty guard (models of format 1.2 and later do; "
           "re-bake to get one).\n\n";
    } else {
      s << "How far each character's pose is from the poses its model was trained on (the model's novelty guard: "
           "distance of the network's input to the nearest training-pose centre; 1 is the sparse edge of the "
           "training set). The guard, which clamps the mesh weights to their training range and blends towards the "
           "mean shape as a pose grows novel, was "
        << (nv["guard"].get<bool>() ? "ON" : "OFF (--no-guard: measured, not applied)") << ". Novelty over "
        << nv["characterFrames"] << " character frames: mean " << fmt(num(nv["overall"]["mean"])) << ", p95 "
        << fmt(num(nv["overall"]["p95"])) << ", max " << fmt(num(nv["overall"]["max"])) << "; "
        << nv["flaggedCharacterFrames"] << " character frames above their model's flag threshold.\n\n"
        << "![novelty per frame](plots/novelty_per_frame.svg)\n\n"
        << "| character | mean | p95 | max | frames flagged |\n|---|---:|---:|---:|---:|\n";
      for (const auto& c : j["characters"]) {
        if (!c.contains("novelty")) continue;
        const json& q = c["novelty"];
        s << "| " << c["name"].get<std::string>() << " | " << fmt(num(q["mean"])) << " | " << fmt(num(q["p95"]))
          << " | " << fmt(num(q["max"])) << " | " << q["framesFlagged"] << " |\n";
      }
      s << "\n";
      if (!nv["flagged"].empty()) {
        s << "First flagged frames:\n\n| frame | character | novelty | blend to the mean shape "
             "|\n|---:|---|---:|---:|\n";
        size_t shown = 0;
        for (const auto& f : nv["flagged"]) {
          if (shown++ == 20) break;
          s << "| " << f["frame"] << " | " << f["character"].get<std::string>() << " | " << fmt(num(f["novelty"]))
            << " | " << fmt(num(f["blend"])) << " |\n";
        }
        s << "\n";
      }
    }
  }
  {
    const json& p = j["penetration"];
    s << "## Garment inside the body\n\nPenetration of the garment into the body it was baked on: "
      << p["note"].get<std::string>() << ". Measured on the CPU reference's positions"
      << (num(p["every"]) > 1 ? " every " + std::to_string(p["every"].get<int>()) + " frames"
                              : std::string(" every frame"))
      << ", per character: vertices inside the body (signed distance < 0), those deeper than "
      << fmt(num(p["visibleDepthMm"]), "%g")
      << " mm (visible), the deepest. The run time's push-out to the body anchors was "
      << (p["pushOut"].get<bool>() ? "ON (what the GPU drew and the truth measured)" : "OFF") << ".\n\n";
    if (p.contains("overall")) {
      s << "| positions | frames x characters | with any inside | with visible (> "
        << fmt(num(p["visibleDepthMm"]), "%g")
        << " mm) | vertices inside | share | visible vertices | deepest mm | p95 of per-frame deepest mm |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
      auto row = [&](const char* label, const json& q) {
        s << "| " << label << " | " << q["frames"] << " | " << q["framesWithInside"] << " | " << q["framesVisible"]
          << " | " << q["inside"] << " | " << fmt(100.0 * num(q["share"]), "%.3f") << " % | " << q["visible"] << " | "
          << fmt(num(q["deepestMm"]), "%.2f") << " | " << fmt(num(q["deepestP95Mm"]), "%.2f") << " |\n";
      };
      row("model (no push-out)", p["overall"]["model"]);
      if (p["overall"].contains("pushed")) row("after the push-out", p["overall"]["pushed"]);
      s << "\n![garment inside the body per frame](plots/penetration_per_frame.svg)\n\n";
      s << "Per character (deepest mm, frames with visible penetration):\n\n| character | model deepest | model frames "
           "visible | "
           "pushed deepest | pushed frames visible |\n|---|---:|---:|---:|---:|\n";
      for (const auto& c : j["characters"]) {
        if (!c.contains("penetration")) continue;
        const json& q = c["penetration"];
        s << "| " << c["name"].get<std::string>() << " | " << fmt(num(q["model"]["deepestMm"]), "%.2f") << " | "
          << q["model"]["framesVisible"] << " | "
          << (q.contains("pushed") ? fmt(num(q["pushed"]["deepestMm"]), "%.2f") : std::string("-")) << " | "
          << (q.contains("pushed") ? q["pushed"]["framesVisible"].dump() : std::string("-")) << " |\n";
      }
      s << "\n";
    }
  }
  s << "Numerical error of the GPU outputs against the CPU reference (" << sum["checkedFrames"] << " checked frames): "
    << "positions max " << fmt(num(sum["gpuVsCpu"]["maxPositionErrorMm"])) << " mm, normals/tangents max "
    << fmt(num(sum["gpuVsCpu"]["maxNormalErrorDeg"])) << " deg, normal maps max " << sum["gpuVsCpu"]["maxMapErrorSteps"]
    << " snorm16 steps.\n\n";
  s << "| stage | median ms / frame | p95 ms / frame |\n|---|---:|---:|\n";
  for (const auto& st : stageColumns())
    s << "| " << st.label << " | " << fmt(num(sum["medianMs"][st.key])) << " | " << fmt(num(sum["p95Ms"][st.key]))
      << " |\n";
  s << "| CPU total | " << fmt(num(sum["medianMs"]["cpuTotal"])) << " | |\n\n";
  s << "![time per frame](plots/time_per_frame.svg)\n\n![time per stage](plots/time_per_stage.svg)\n\n"
    << "![GPU vs CPU error per frame](plots/error_per_frame.svg)\n\n![error against time](plots/error_vs_time.svg)\n\n";
  s << "## Characters\n\n| character | model | on screen | checks | max position error mm | max normal error deg | max "
       "map error | pose issues |\n"
    << "|---|---|---|---:|---:|---:|---:|---:|\n";
  for (const auto& c : j["characters"])
    s << "| " << c["name"].get<std::string>() << " | " << c["model"].get<std::string>() << " | "
      << (c["onScreen"].get<bool>() ? "yes" : "no") << " | " << c["checks"] << " | "
      << fmt(num(c["maxPositionErrorMm"])) << " | " << fmt(num(c["maxNormalErrorDeg"])) << " | "
      << c["maxMapErrorSteps"] << " | " << c["poseIssues"] << " |\n";
  if (j["truth"].contains("overall")) {
    s << "\n### Ground truth per character\n\n| character | measured | failed | mean mm | p95 mm | max mm | map mean "
         "deg | map p95 deg |\n"
      << "|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const auto& c : j["characters"]) {
      if (!c.contains("truth")) continue;
      const json& t = c["truth"];
      if (num(t["samples"]) + num(t["failed"]) == 0) continue;
      auto cell = [&](const char* k) { return t.contains(k) ? fmt(num(t[k])) : std::string("-"); };
      s << "| " << c["name"].get<std::string>() << " | " << t["samples"] << " | " << t["failed"] << " | "
        << cell("meanMm") << " | " << cell("p95Mm") << " | " << cell("maxMm") << " | " << cell("normalMeanDeg") << " | "
        << cell("normalP95Deg") << " |\n";
    }
    size_t failures = 0;
    for (const auto& f : j["frames"])
      for (const auto& t : f.value("truth", json::array()))
        if (!t["ok"].get<bool>() && ++failures <= 50)
          s << (failures == 1 ? "\nTruth simulations that failed (no truth for that frame and character):\n\n" : "")
            << "- frame " << f["frame"] << ", " << t["character"].get<std::string>() << ": "
            << t.value("failure", std::string()) << "\n";
    if (failures > 50) s << "- ... (" << failures << " in all; every one in report.json)\n";
  }
  s << "\n## Bad poses and failures\n\n"
    << sum["poseIssues"] << " pose issues, " << sum["failures"] << " check failures.\n\n";
  size_t shown = 0;
  for (const auto& i : j["issues"]) {
    if (++shown > 50) {
      s << "- ... (all in report.json)\n";
      break;
    }
    s << "- frame " << i["frame"] << ", " << i["character"].get<std::string>()
      << (i["joint"].get<std::string>().empty() ? "" : ", joint " + i["joint"].get<std::string>()) << ": "
      << i["problem"].get<std::string>() << " -> " << i["action"].get<std::string>() << "\n";
  }
  for (const auto& f : j["failures"]) s << "- " << f.get<std::string>() << "\n";
  return s.str();
}

void writeReport(const std::filesystem::path& dir, const runtime::Scene& scene, const ModelLibrary& models,
                 const ReplayResult& r) {
  const json j = reportJson(scene, models, r);
  std::filesystem::create_directories(dir / "plots");
  using io::PlotSeries;
  PlotSeries cpu{"CPU total", {}, {}, ""}, gpu{"GPU total", {}, {}, ""}, wall{"submit to fence", {}, {}, ""};
  PlotSeries pos{"positions (mm)", {}, {}, ""}, deg{"normals (deg)", {}, {}, ""}, vsTime{"checked frames", {}, {}, ""};
  vsTime.markers = true;
  PlotSeries truthMean{"mean over characters", {}, {}, ""}, truthMax{"worst character's max", {}, {}, ""};
  PlotSeries truthVsTime{"truth frames: mean vertex error against ground truth (mm)", {}, {}, ""};
  PlotSeries truthDeg{"normal-map mean angular error, mean over characters (deg)", {}, {}, ""};
  truthMean.markers = truthMax.markers = truthVsTime.markers = truthDeg.markers = true;
  for (const auto& f : r.frames) {
    const auto [mean, worst] = frameTruthMm(f);
    if (!std::isfinite(mean)) continue;
    truthMean.x.push_back(f.frame), truthMean.y.push_back(mean);
    truthMax.x.push_back(f.frame), truthMax.y.push_back(worst);
    truthVsTime.x.push_back(f.times.cpuTotal() + (std::isfinite(f.times.gpuTotal) ? f.times.gpuTotal : 0.0));
    truthVsTime.y.push_back(mean);
    double deg = 0;
    int n = 0;
    for (const auto& c : f.truth)
      if (c.ok && c.normalMap) deg += c.meanDeg, ++n;
    if (n) truthDeg.x.push_back(f.frame), truthDeg.y.push_back(deg / n);
  }
  for (const auto& f : r.frames) {
    const double x = f.frame;
    cpu.x.push_back(x), cpu.y.push_back(f.times.cpuTotal());
    gpu.x.push_back(x), gpu.y.push_back(f.times.gpuTotal);
    wall.x.push_back(x), wall.y.push_back(f.times.gpuWait);
    if (f.checked) {
      pos.x.push_back(x), pos.y.push_back(f.maxPositionErrorMm());
      deg.x.push_back(x), deg.y.push_back(f.maxNormalErrorDeg());
      vsTime.x.push_back(f.times.cpuTotal() + (std::isfinite(f.times.gpuTotal) ? f.times.gpuTotal : 0.0));
      vsTime.y.push_back(f.maxPositionErrorMm());
    }
  }
  auto plot = [](const char* title, const char* xLabel, const char* yLabel, std::vector<PlotSeries> series) {
    io::SvgPlot p;
    p.title = title, p.xLabel = xLabel, p.yLabel = yLabel;
    p.yFromZero = true;
    p.width = 720, p.height = 360;
    p.series = std::move(series);
    return p.render();
  };
  writeTextFileAtomic(dir / "plots/time_per_frame.svg", plot("Time per frame", "scene frame", "ms", {cpu, gpu, wall}));
  writeTextFileAtomic(dir / "plots/error_per_frame.svg",
                      plot("GPU vs CPU reference, worst character", "scene frame", "error", {pos, deg}));
  std::vector<PlotSeries> vsTimeSeries{vsTime};
  if (!truthVsTime.x.empty()) vsTimeSeries.push_back(truthVsTime);
  writeTextFileAtomic(
      dir / "plots/error_vs_time.svg",
      plot(truthVsTime.x.empty() ? "Error against run time (checked frames)"
                                 : "Error against run time (checked frames: GPU vs CPU; truth frames: vs ground truth)",
           "CPU + GPU ms per frame", "position error (mm)", vsTimeSeries));
  if (!truthMean.x.empty()) {
    std::vector<PlotSeries> ts{truthMean, truthMax};
    if (!truthDeg.x.empty()) ts.push_back(truthDeg);
    writeTextFileAtomic(dir / "plots/truth_error_per_frame.svg",
                        plot("Run time against ground truth (source simulation), per truth frame", "scene frame",
                             "vertex error (mm); normal maps (deg)", ts));
  }
  if (num(j["novelty"]["characterFrames"]) > 0) {
    // One line per character up to 12 characters; beyond that the worst and the median per frame.
    constexpr size_t kMaxLines = 12;
    std::vector<uint32_t> shown;
    for (const auto& f : r.frames)
      for (const auto& nv : f.novelty)
        if (std::find(shown.begin(), shown.end(), nv.character) == shown.end()) shown.push_back(nv.character);
    std::vector<PlotSeries> ns;
    if (shown.size() <= kMaxLines) {
      for (uint32_t c : shown) ns.push_back({scene.characters[c].name, {}, {}, ""});
      for (const auto& f : r.frames)
        for (const auto& nv : f.novelty) {
          const size_t k = size_t(std::find(shown.begin(), shown.end(), nv.character) - shown.begin());
          ns[k].x.push_back(f.frame), ns[k].y.push_back(nv.novelty);
        }
    } else {
      PlotSeries worst{"worst character", {}, {}, ""}, median{"median character", {}, {}, ""};
      for (const auto& f : r.frames) {
        if (f.novelty.empty()) continue;
        std::vector<double> v;
        for (const auto& nv : f.novelty) v.push_back(nv.novelty);
        worst.x.push_back(f.frame), worst.y.push_back(*std::max_element(v.begin(), v.end()));
        median.x.push_back(f.frame), median.y.push_back(quantile(v, 0.5));
      }
      ns = {worst, median};
    }
    writeTextFileAtomic(
        dir / "plots/novelty_per_frame.svg",
        plot("Novelty per character (1: the sparse edge of the training poses)", "scene frame", "novelty", ns));
  }
  if (!r.penetrationPerCharacter.empty()) {
    PlotSeries deepModel{"deepest, model (mm)", {}, {}, ""}, deepPushed{"deepest, after the push-out (mm)", {}, {}, ""};
    PlotSeries visModel{"visible vertices, model (sum over characters / 10)", {}, {}, ""};
    PlotSeries visPushed{"visible vertices, after the push-out (sum / 10)", {}, {}, ""};
    for (const auto& f : r.frames) {
      if (f.penetration.empty()) continue;
      double dm = 0, dp = 0, vm = 0, vp = 0;
      bool pushed = false;
      for (const auto& p : f.penetration) {
        dm = std::max(dm, p.model.deepestMm), vm += p.model.visible;
        if (p.pushedMeasured) pushed = true, dp = std::max(dp, p.pushed.deepestMm), vp += p.pushed.visible;
      }
      deepModel.x.push_back(f.frame), deepModel.y.push_back(dm);
      visModel.x.push_back(f.frame), visModel.y.push_back(vm / 10.0);
      if (pushed)
        deepPushed.x.push_back(f.frame), deepPushed.y.push_back(dp), visPushed.x.push_back(f.frame),
            visPushed.y.push_back(vp / 10.0);
    }
    std::vector<PlotSeries> ps{deepModel, visModel};
    if (!deepPushed.x.empty()) ps.push_back(deepPushed), ps.push_back(visPushed);
    writeTextFileAtomic(
        dir / "plots/penetration_per_frame.svg",
        plot("Garment inside the body, worst character per frame", "scene frame", "mm; vertices / 10", ps));
  }
  if (!r.levelCharacters.empty()) {
    // Levels over time: up to 12 characters one line each, else the mean level; the budget's prediction
    // and the measured GPU time beside them.
    std::vector<PlotSeries> ls;
    if (r.levelCharacters.size() <= 12) {
      for (uint32_t c : r.levelCharacters) ls.push_back({scene.characters[c].name, {}, {}, ""});
      for (const auto& f : r.frames)
        for (size_t s = 0; s < f.levels.size() && s < ls.size(); ++s)
          ls[s].x.push_back(f.frame), ls[s].y.push_back(f.levels[s]);
    } else {
      PlotSeries mean{"mean level over characters", {}, {}, ""}, worst{"cheapest level", {}, {}, ""};
      for (const auto& f : r.frames) {
        if (f.levels.empty()) continue;
        double sum = 0, mx = 0;
        for (uint8_t l : f.levels) sum += l, mx = std::max(mx, double(l));
        mean.x.push_back(f.frame), mean.y.push_back(sum / double(f.levels.size()));
        worst.x.push_back(f.frame), worst.y.push_back(mx);
      }
      ls = {mean, worst};
    }
    PlotSeries predicted{"predicted GPU ms", {}, {}, ""}, measured{"measured GPU ms", {}, {}, ""};
    for (const auto& f : r.frames)
      if (!f.levels.empty())
        predicted.x.push_back(f.frame), predicted.y.push_back(f.predictedGpuMs), measured.x.push_back(f.frame),
            measured.y.push_back(f.times.gpuTotal);
    if (!predicted.x.empty()) ls.push_back(predicted);
    ls.push_back(measured);
    writeTextFileAtomic(dir / "plots/levels_per_frame.svg",
                        plot("Quality level per character (0 = full) and GPU time", "scene frame", "level; ms", ls));
  }
  io::SvgBarChart stages;
  stages.title = "Median time per stage", stages.unit = "ms";
  for (const auto& st : stageColumns()) {
    stages.labels.push_back(st.label);
    stages.values.push_back(num(j["summary"]["medianMs"][st.key]));
  }
  writeTextFileAtomic(dir / "plots/time_per_stage.svg", stages.render());
  writeTextFileAtomic(dir / "report.json", j.dump(2));
  writeTextFileAtomic(dir / "report.md", reportMarkdown(j));
}

}  // namespace swish::replay
