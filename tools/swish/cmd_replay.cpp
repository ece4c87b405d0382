// swish replay: replays a scene headlessly (CPU MLP, lookup and filter; GPU passes on the selected
// Vulkan device) and reports error against run time. With no scene, the default football play
// (assets/scenes/football.json: 22 characters wearing the default model, CMU mocap).
//
// --truth-every N runs the bake's source simulation of the model on every Nth frame and reports the
// per-vertex and normal-map error of the run time against it (replay/truth_simulation.hpp): about two
// seconds of CPU per character and truth frame at the default model's 6568 simulation vertices, run in
// parallel.
//
// Penetration of the garment into the body it was baked on is measured every frame (on the CPU
// reference's positions, before and after the run time's push-out to the model's body anchors) and
// reported with a plot; --penetration-every N thins that, 0 turns it off; --push-out runs the GPU with
// the push-out to the model's body anchors (off by default).
//
// Exit codes: 0 all frames replayed and every check within tolerance; 3 replayed, but bad poses were
// met or a GPU output differed from the CPU reference beyond tolerance (see the report); 1 an error
// (bad scene, missing file, no device): nothing was written.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_job.hpp"
#include "swish/replay/replay_plan.hpp"
#include "swish/replay/replay_render.hpp"
#include "swish/runtime/level_planner.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/scene_file.hpp"
#include "swish/truth_options.hpp"

namespace {

namespace fs = std::filesystem;

struct ReplayCliOptions {
  std::string scene, out, device;
  bool plan = false, quiet = false, validation = false, render = false;
  uint32_t truthEvery = 0, frames = 0, renderCharacter = 0, renderFrames = 16, penetrationEvery = 30;
  std::vector<uint32_t> renderSize = {swish::replay::ReplayRenderOptions{}.width,
                                      swish::replay::ReplayRenderOptions{}.height};
  bool pushOut = false, noPushOut = false, noGuard = false, hideCoveredBody = false, showCoveredBody = false;
  swish::replay::TruthOptions truth;  // the overrides (truth_options.hpp); `every` comes from truthEvery
  std::optional<double> frameBudgetMs, tolerancePixels;
  std::string level;
};

// `--plan`'s quality levels: the planner on the first frame, each character at its placement (the clips'
// root motion is not read without a replay); the budget needs costs, which only a replay calibrates, or
// a ladder whose GPU times were measured.
void printPlannedLevels(const swish::runtime::Scene& scene, swish::replay::ModelLibrary& models,
                        const swish::replay::ReplayPlan& plan, const ReplayCliOptions& o) {
  using namespace swish;
  std::vector<runtime::QualityLadder> ladders;
  std::vector<const runtime::QualityLadder*> per;
  std::vector<std::optional<uint32_t>> fixed;
  std::vector<Eigen::Vector3d> roots;
  std::vector<uint32_t> characters;
  ladders.reserve(plan.batches.size());
  for (const replay::PlannedBatch& b : plan.batches) {
    ladders.push_back(runtime::ladderOf(models.at(b.model).model, b.normalMaps));
  }
  runtime::LevelCosts costs;
  bool timed = true;
  for (size_t b = 0; b < plan.batches.size(); ++b)
    for (uint32_t c : plan.batches[b].characters) {
      const runtime::SceneCharacter& ch = scene.characters[c];
      per.push_back(&ladders[b]);
      const std::string& name = o.level.empty() ? ch.level : o.level;
      fixed.push_back(name.empty()
                          ? std::nullopt
                          : std::optional<uint32_t>(runtime::levelIndex(ladders[b], name, ch.name + " level")));
      roots.push_back(ch.placement.translation + Eigen::Vector3d(0, 1, 0));
      characters.push_back(c);
      std::vector<double> ms;
      for (const runtime::QualityLevel& l : ladders[b].levels) ms.push_back(l.gpuUsPerCharacter / 1000.0);
      for (double v : ms) timed &= std::isfinite(v);
      costs.msPerCharacter.push_back(ms);
    }
  if (per.empty()) return;
  const runtime::LevelPlannerSettings ls = scene.levelPlannerSettings(o.frameBudgetMs, o.tolerancePixels);
  runtime::LevelPlanner planner(per, fixed, ls);
  if (timed) planner.setCosts(costs);
  const runtime::PlannedLevels& p = planner.plan(scene.firstFrame, roots);
  std::printf("\nQuality levels (first frame, characters at their placements):\n");
  for (size_t b = 0; b < plan.batches.size(); ++b) {
    std::printf("  model '%s' ladder:", plan.batches[b].model.c_str());
    for (size_t l = 0; l < ladders[b].size(); ++l)
      std::printf(" %zu %s (k %u%s)%s", l, ladders[b][l].name.c_str(), ladders[b][l].meshComponents,
                  ladders[b][l].normalMaps ? ", maps" : "", l + 1 < ladders[b].size() ? "," : "\n");
  }
  if (ls.frameBudgetMs)
    std::printf("  frame budget %.2f ms: %s\n", *ls.frameBudgetMs,
                timed
                    ? "costs from the ladder's measured GPU times"
                    : "not applied here: the replay calibrates the costs on its device (the ladder has no GPU times)");
  for (size_t s = 0; s < p.characters.size(); ++s) {
    const runtime::LevelChoice& c = p.characters[s];
    std::printf("  %-12s level %u %-10s %6.1f px tall at %5.1f m: %s\n", scene.characters[characters[s]].name.c_str(),
                c.level, (*per[s])[c.level].name.c_str(), c.view.heightPixels, c.view.distance, c.reason.c_str());
  }
  if (std::isfinite(p.weightedErrorMm))
    std::printf("  screen-weighted ladder error %.2f mm (full quality %.2f mm)\n", p.weightedErrorMm, p.fullErrorMm);
}

fs::path defaultScenePath() {
  std::error_code ec;
  for (const fs::path& root : swish::replay::assetSearchRoots())
    if (fs::exists(root / "assets/scenes/football.json", ec)) return root / "assets/scenes/football.json";
  throw swish::Error(
      "no scene given and the default scene assets/scenes/football.json was not found (looked in the "
      "current folder and beside the swish executable)");
}

int runReplay(const ReplayCliOptions& o) {
  using namespace swish;
  const bool isDefault = o.scene.empty();
  runtime::Scene scene = runtime::loadScene(isDefault ? defaultScenePath() : fs::path(o.scene));
  if (!o.out.empty())
    scene.outputs.directory = fs::absolute(o.out);
  else if (isDefault)
    scene.outputs.directory = fs::current_path() / "replay-out";  // not into the source tree
  if (o.frames > 0) scene.frameCount = o.frames;
  if (o.pushOut || o.noPushOut) scene.body.pushOut = o.pushOut;  // the command line over the scene
  if (o.hideCoveredBody || o.showCoveredBody) scene.body.hideCovered = o.hideCoveredBody;
  replay::ModelLibrary models(scene);  // loaded once: plan, replay and render share it

  if (o.plan) {
    const replay::ReplayPlan plan = replay::planReplay(scene, models.modelMap());
    std::printf("Scene '%s' (%s): %zu characters, frames %u..%u at %g fps\n", scene.name.c_str(),
                scene.source.string().c_str(), scene.characters.size(), scene.firstFrame,
                scene.firstFrame + scene.frameCount - 1, scene.framesPerSecond);
    for (const auto& e : models.entries()) std::printf("Model '%s': %s\n", e->key.c_str(), e->label.c_str());
    std::printf("%s", plan.describe().c_str());
    printPlannedLevels(scene, models, plan, o);
    return 0;
  }
  replay::ReplayJobOptions jo;
  jo.quiet = o.quiet;
  jo.models = &models;
  jo.engine.device.device = o.device;
  if (o.validation) jo.engine.device.validation = true;
  jo.engine.truth = o.truth;
  jo.engine.truth.every = o.truthEvery;
  jo.engine.penetrationEvery = o.penetrationEvery;
  jo.engine.pushOut = scene.body.pushOut;
  jo.engine.noveltyGuard = !o.noGuard;
  jo.engine.frameBudgetMs = o.frameBudgetMs;
  jo.engine.tolerancePixels = o.tolerancePixels;
  jo.engine.fixedLevel = o.level;
  const replay::ReplayJobResult r = replay::runReplayJob(scene, jo);
  if (!o.quiet) {
    std::printf("Replayed %zu frames of '%s' on %s.\n", r.result.frames.size(), scene.name.c_str(),
                r.result.device.c_str());
    if (!r.directory.empty()) std::printf("Report: %s\n", (r.directory / "report.md").string().c_str());
    std::printf("%zu pose issues, %zu check failures.\n", r.result.issueCount, r.result.failures.size());
    const replay::TruthSummary& t = r.result.truthOverall;
    if (t.samples + t.failed > 0) {
      std::printf(
          "Ground truth on %u frames: %u character poses simulated (%u failed), %.1f s wall in all, %.2f s CPU "
          "per pose",
          r.result.truthFrames, t.samples + t.failed, t.failed, r.result.truthWallSeconds,
          t.cpuSeconds / double(t.samples + t.failed));
      if (t.samples > 0)
        std::printf("; vertex error mean %.2f mm, p95 %.2f mm, max %.2f mm", t.meanMm, t.p95Mm, t.maxMm);
      if (t.samples > 0 && t.normalMaps) std::printf("; normal maps mean %.2f deg, p95 %.2f deg", t.meanDeg, t.p95Deg);
      std::printf(".\n");
    }
    std::printf("Ground truth: %s\n", r.result.truthNote.c_str());
    if (!r.result.penetrationPerCharacter.empty()) {
      auto line = [](const char* what, const bake::PenetrationPool& p) {
        std::printf(
            "Garment inside the body, %s: %u of %u character frames with a vertex deeper than %g mm, deepest %.1f mm, "
            "p95 of the per-frame deepest %.1f mm, %.3f %% of vertices inside.\n",
            what, p.framesVisible, p.frames, bake::kVisiblePenetrationMm, p.deepestMm, p.deepestPercentileMm(0.95),
            100.0 * p.share());
      };
      line("model", r.result.penetrationOverall.model);
      if (r.result.penetrationOverall.pushedMeasured) line("after the push-out", r.result.penetrationOverall.pushed);
    } else {
      std::printf("Penetration: %s\n", r.result.penetrationNote.c_str());
    }
    size_t measured = 0, flagged = 0;
    float worst = 0.f;
    for (const auto& f : r.result.frames)
      for (const auto& nv : f.novelty) ++measured, flagged += nv.flagged, worst = std::max(worst, nv.novelty);
    if (measured > 0)
      std::printf("Novelty: %zu of %zu character frames above the flag threshold, highest %.2f; guard %s.\n", flagged,
                  measured, double(worst), o.noGuard ? "off (--no-guard)" : "on");
    else
      std::printf("Novelty: not measured (no model in the scene carries a novelty guard).\n");
    const replay::ReplayResult& rr = r.result;
    if (!rr.levels.empty() && !rr.frames.empty()) {
      double gpu = 0, predicted = 0, weighted = 0, full = 0;
      size_t nGpu = 0, nPred = 0, nErr = 0, changes = 0;
      for (const auto& f : rr.frames) {
        if (std::isfinite(f.times.gpuTotal)) gpu += f.times.gpuTotal, ++nGpu;
        if (std::isfinite(f.predictedGpuMs)) predicted += f.predictedGpuMs, ++nPred;
        if (std::isfinite(f.weightedErrorMm)) weighted += f.weightedErrorMm, full += f.fullErrorMm, ++nErr;
        changes += f.levelChanges;
      }
      std::printf("Quality levels: %zu level changes", changes);
      if (rr.frameBudgetMs) std::printf("; budget %.2f ms", *rr.frameBudgetMs);
      if (nPred > 0) std::printf(", predicted %.2f ms", predicted / double(nPred));
      if (nGpu > 0) std::printf(", measured GPU %.2f ms mean per frame", gpu / double(nGpu));
      if (nErr > 0)
        std::printf("; screen-weighted ladder error %.2f mm (full quality %.2f mm)", weighted / double(nErr),
                    full / double(nErr));
      std::printf(".\n");
    }
  }
  if (o.render) {
    // After the replay's outputs are in place, so that a render failure never loses the report.
    const fs::path dir = (r.directory.empty() ? fs::path(scene.outputs.directory) : r.directory) / "render";
    replay::ReplayRenderOptions ro;
    ro.character = o.renderCharacter;
    ro.maxFrames = o.renderFrames;
    ro.width = o.renderSize[0];
    ro.height = o.renderSize[1];
    ro.device = o.device;
    ro.validation = o.validation;
    ro.truth = jo.engine.truth;
    ro.pushOut = scene.body.pushOut;
    ro.hideCoveredBody = scene.body.hideCovered;
    const replay::ReplayRenderResult rr = replay::renderReplayFrames(scene, models, dir, ro);
    const fs::path report = dir.parent_path() / "report.md";
    if (std::ifstream in(report); in) {  // the pictures' section at the end of the report: what they show
      std::ostringstream text;
      text << in.rdbuf();
      writeTextFileAtomic(report, text.str() + replay::renderReportSection(rr, ro, dir.parent_path()));
    }
    if (!o.quiet) {
      std::printf("Rendered %zu frames of character %u: %s\n", rr.frames.size(), o.renderCharacter,
                  rr.contactSheet.string().c_str());
      if (!rr.heatSheet.empty())
        std::printf("Error heat maps of %zu truth frames (model | truth | error, mm): %s\n", rr.heatMaps.size(),
                    rr.heatSheet.string().c_str());
      if (!rr.note.empty()) std::printf("%s\n", rr.note.c_str());
    }
  }
  return r.result.failed() ? 3 : 0;
}

swish::cli::CommandRegistration reg{
    "replay", "Replay a scene headlessly and report error against run time (default: the football play)",
    [](CLI::App& app) -> swish::cli::RunFn {
      auto o = std::make_shared<ReplayCliOptions>();
      app.add_option("scene", o->scene,
                     "scene file (JSON; see src/swish/runtime/scene_file.hpp). Default: assets/scenes/football.json");
      app.add_flag("--plan", o->plan, "print the planned work (stages, dispatches, memory, what is left out) and exit");
      app.add_option("--out", o->out, "output folder (overrides the scene's outputs.directory)");
      app.add_option("--device", o->device,
                     "Vulkan device: index or name substring (default: SWISH_DEVICE, else automatic)");
      app.add_option(
          "--truth-every", o->truthEvery,
          "ground truth: run the bake's source cloth simulation on every Nth frame and report the per-vertex "
          "(mm) and normal-map (deg) error of the run time against it (about 2 s of CPU per character and truth frame "
          "with "
          "the default model, in parallel)");
      // --truth-cover-mm with --render: the report counts the truth's body-through pixels too.
      swish::cli::addTruthOverrideOptions(app, o->truth, "the report");
      app.add_option(
          "--penetration-every", o->penetrationEvery,
          "measure the garment inside the body it was baked on (CPU reference, before and after the push-out) "
          "on every Nth frame; 0: not at all (default 30: the measure poses a body collider per character, costly on "
          "the CPU)");
      auto* push = app.add_flag("--push-out", o->pushOut,
                                "keep the garment off the body on the GPU: each vertex outside its body anchors' "
                                "balls (models that carry anchors, format 1.3 and later: `swish body-proxy` adds "
                                "them; default: the scene's body.pushOut, else off)");
      app.add_flag("--no-push-out", o->noPushOut, "no push-out, whatever the scene says")->excludes(push);
      auto* hide = app.add_flag(
          "--hide-covered-body", o->hideCoveredBody,
          "with --render: leave out the body triangles the garment covers in (nearly) every training pose (the "
          "model's list, as games do under tight clothing); default: the scene's body.hideCovered, else off so that "
          "a fault shows");
      app.add_flag("--show-covered-body", o->showCoveredBody,
                   "with --render: draw the whole body, whatever the scene says")
          ->excludes(hide);
      app.add_flag("--no-guard", o->noGuard,
                   "measure each character's novelty (how far its pose is from the model's training poses) but do "
                   "not apply the model's novelty guard (clamp of the mesh weights, blend towards the mean shape): "
                   "with --truth-every, shows what the guard does to the error");
      app.add_option("--frame-budget-ms", o->frameBudgetMs,
                     "GPU milliseconds per frame for all characters: the level planner steps characters down "
                     "(small and far first) until its calibrated prediction fits (overrides the scene's "
                     "levels.frameBudgetMs)");
      app.add_option("--level-tolerance-px", o->tolerancePixels,
                     "each character runs at the cheapest quality level whose mean error on screen is within "
                     "this many pixels (overrides the scene's levels.tolerancePixels)");
      app.add_option("--level", o->level,
                     "every character at this quality level of its model's ladder (a name such as k64 or "
                     "skinned, or an index; `swish inspect MODEL` lists them)");
      app.add_option("--frames", o->frames, "replay only this many frames");
      app.add_flag("--quiet", o->quiet, "no progress bar or summary");
      app.add_flag("--validation", o->validation, "enable the Vulkan validation layers");
      app.add_flag(
          "--render", o->render,
          "also draw one character with the preview renderer: PNG frames + contact_sheet.png in <out>/render/");
      app.add_option("--render-character", o->renderCharacter,
                     "scene character index to draw with --render (default 0)");
      app.add_option("--render-frames", o->renderFrames, "at most this many frames, spread over the scene (default 16)")
          ->check(CLI::Range(1u, 10000u));
      app.add_option("--render-size", o->renderSize,
                     "WIDTH HEIGHT of each frame in pixels (default " +
                         std::to_string(swish::replay::ReplayRenderOptions{}.width) + " " +
                         std::to_string(swish::replay::ReplayRenderOptions{}.height) +
                         "; the contact sheet holds 16 of them): "
                         "larger to look at a fault up close")
          ->expected(2)
          ->check(CLI::Range(16u, 4096u));
      return [o] { return runReplay(*o); };
    }};

}  // namespace
