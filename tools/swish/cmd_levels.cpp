// swish levels MODEL [--clips A.bvh ...]: measures the quality levels of a model already baked
// (runtime/quality_levels.hpp, bake/report/quality_ladder.hpp) and writes the model with the measured
// ladder in its metadata. `swish bake` measures the ladder itself on its held-out poses; a model baked
// before it (like the committed default, whose bake dataset is gone) gets it here, against the bake's own
// source simulation (bake/pipeline/pose_shape.hpp, rebuilt from the model's metadata as `swish replay
// --truth-every` rebuilds it) of frames of clips: by default the clips the model was baked from.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/bake/poses/clip_list.hpp"
#include "swish/bake/report/quality_ladder.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/truth_simulation.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/truth_options.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

struct LevelsCliOptions {
  std::string model, out, report;
  std::vector<std::string> clips;
  size_t frames = 40;
  size_t every = 0;
  swish::replay::TruthOptions truth;  // the overrides (truth_options.hpp)
  int threads = 0;
};

std::string f2(double v) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

// One frame of one clip.
struct FrameRef {
  size_t clip = 0, frame = 0;
};

// The frames to simulate: frame 0 of each clip is left out (the CMU conversions put a reference T-pose
// there, as part 1's evenly spaced frames do); with `every` only frames every..., 2 x every, ...; then at
// most `count` of them, evenly spaced over what is left.
std::vector<FrameRef> chooseFrames(const std::vector<swish::AnimationClip>& clips, size_t count, size_t every) {
  std::vector<FrameRef> all;
  for (size_t c = 0; c < clips.size(); ++c)
    for (size_t f = 1; f < clips[c].frames.size(); ++f)
      if (every == 0 || f % every == 0) all.push_back({c, f});
  if (all.size() <= count) return all;
  std::vector<FrameRef> out;
  for (size_t i = 0; i < count; ++i) out.push_back(all[(2 * i + 1) * all.size() / (2 * count)]);
  return out;
}

int runLevels(const LevelsCliOptions& o) {
  using namespace swish;
  const auto t0 = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  replay::ModelEntry entry = replay::loadModelEntry(o.model);
  Model& model = entry.model;
  const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);

  // The bake's source simulation, as `swish replay --truth-every` rebuilds it (replay::ModelTruth).
  const json meta = json::parse(model.metadata, nullptr, false);
  const json ds = meta.is_object() && meta.contains("dataset_settings") && meta["dataset_settings"].is_object()
                      ? meta["dataset_settings"]
                      : json::object();
  const replay::ModelTruth simulator(entry, o.truth);
  if (!simulator.available()) throw Error(o.model + ": no truth to measure the levels against: " + simulator.note());
  const std::string& truth = simulator.note();

  // Clips: those given, else the model's own (its bake's part1.clips, as the metadata names them).
  std::vector<bake::ClipSource> sources;
  const bool ownClips = o.clips.empty();
  if (ownClips) {
    if (!ds.contains("clips") || !ds["clips"].is_array() || ds["clips"].empty())
      throw Error(o.model + ": the metadata names no clips the model was baked from; give some with --clips");
    sources =
        bake::parseClipList(ds["clips"], o.model + ": metadata dataset_settings.clips: ", entry.file.parent_path());
  } else {
    for (const std::string& c : o.clips) {
      if (!fs::is_regular_file(c)) throw Error("--clips: " + c + " does not exist");
      bake::ClipSource s;
      s.file = c;
      s.subject = bake::subjectOfClipFile(c);
      sources.push_back(std::move(s));
    }
  }
  std::vector<std::string> inputNames;
  for (uint32_t j : model.inputJoints) inputNames.push_back(model.skeleton.joints[j].name);
  const std::vector<AnimationClip> clips = bake::importClips(
      sources, model.skeleton, inputNames, o.threads, [](const std::string& l) { std::printf("%s\n", l.c_str()); });
  const std::vector<FrameRef> frames = chooseFrames(clips, o.frames, o.every);
  if (frames.empty())
    throw Error("the clips hold no frame to measure on (frame 0 of each is left out" +
                std::string(o.every ? ", and only every " + std::to_string(o.every) + "th frame is taken" : "") + ")");
  std::string clipNames;
  for (const auto& s : sources) clipNames += (clipNames.empty() ? "" : ", ") + s.file.filename().string();
  size_t clipFrames = 0;
  for (const auto& c : clips) clipFrames += c.frames.size();

  std::printf("Model %s: K = %d, %u normal maps; %zu levels (%s)\n", o.model.c_str(), model.meshComponents(),
              model.normalMaps.mapCount(), runtime::ladderOf(model).size(),
              meta.is_object() && meta.contains(runtime::kQualityLevelsKey) ? "its stored ladder, measured again"
                                                                            : "the default ladder");
  std::printf("Truth: %s.\n", truth.c_str());
  std::printf("Poses: %zu frames of %s (%zu frames), evenly spaced%s.\n", frames.size(), clipNames.c_str(), clipFrames,
              o.every ? (" over every " + std::to_string(o.every) + "th frame").c_str() : "");
  if (ownClips)
    std::printf(
        "  These are the clips the model was baked from. The bake sampled them (speed jitter, mirrored characters) "
        "and thinned the samples to its pose list, so a clip frame is in general not a training pose: like the bake "
        "report's held-out poses, these are random frames of the training clips (the same motion, not unseen "
        "motion).\n");
  std::printf(
      "Simulating %zu truth poses (a few seconds of CPU each) on %s...\n", frames.size(),
      o.threads > 0 ? (std::to_string(o.threads) + (o.threads == 1 ? " thread" : " threads")).c_str() : "all cores");
  std::fflush(stdout);

  // The truth of each frame, in parallel; progress with the time left.
  std::vector<std::optional<bake::DatasetPose>> truths(frames.size());
  std::vector<std::string> failures(frames.size());
  std::mutex printMutex;
  std::atomic<size_t> done{0}, failed{0};
  const auto tSim = Clock::now();
  const auto one = [&](size_t i) {
    const Pose& pose = clips[frames[i].clip].frames[frames[i].frame];
    const bake::PoseShape shape = simulator.simulate(pose);
    if (shape.ok) {
      bake::DatasetPose p;
      p.id = uint32_t(i);
      p.pose = pose;
      p.gameMeshPreSkin = shape.gameMeshPreSkin;
      p.gameMeshWorld = shape.gameMeshWorld;
      p.normalMap = shape.normalMap;
      truths[i] = std::move(p);
    } else {
      failures[i] = shape.failure;
      ++failed;
    }
    const size_t d = ++done;
    const double el = std::chrono::duration<double>(Clock::now() - tSim).count();
    std::lock_guard<std::mutex> lock(printMutex);
    std::printf("  truth %zu/%zu (%s frame %zu)%s: %.1f s elapsed, about %.0f s left\n", d, frames.size(),
                clips[frames[i].clip].name.c_str(), frames[i].frame, shape.ok ? "" : " FAILED", el,
                el / double(d) * double(frames.size() - d));
    std::fflush(stdout);
  };
  if (o.threads > 0) {
    tbb::task_arena arena(o.threads);
    arena.execute([&] { tbb::parallel_for(size_t(0), frames.size(), size_t(1), one); });
  } else {
    tbb::parallel_for(size_t(0), frames.size(), size_t(1), one);
  }
  std::vector<const bake::DatasetPose*> poses;
  std::vector<const Pose*> posePtrs;
  for (const auto& t : truths)
    if (t) poses.push_back(&*t), posePtrs.push_back(&t->pose);
  std::string firstFailure;
  for (size_t i = 0; i < frames.size() && firstFailure.empty(); ++i)
    if (!failures[i].empty())
      firstFailure = clips[frames[i].clip].name + " frame " + std::to_string(frames[i].frame) + ": " + failures[i];
  if (poses.empty())
    throw Error("none of the " + std::to_string(frames.size()) + " truth simulations succeeded (" + firstFailure +
                "): nothing to measure the levels on");
  if (failed > 0)
    std::printf("%zu of %zu truth simulations failed and are left out (as the bake leaves such poses out), e.g. %s\n",
                size_t(failed), frames.size(), firstFailure.c_str());

  const std::string measuredOn = std::to_string(poses.size()) + " frames of " +
                                 (ownClips ? "the model's training clips " : "the clips ") + clipNames +
                                 " (swish levels; truth: " + truth + ")";
  runtime::QualityLadder ladder = bake::measureLadder(model, poses, measuredOn);
  std::printf("Timing the run-time CPU path per level...\n");
  std::fflush(stdout);
  bake::timeLadderCpu(model, posePtrs, ladder);

  std::printf("\n%-12s %5s %5s %10s %8s %8s %10s %10s\n", "level", "k", "maps", "mean mm", "p95 mm", "max mm",
              "normal deg", "CPU us");
  for (const runtime::QualityLevel& l : ladder.levels)
    std::printf("%-12s %5u %5s %10s %8s %8s %10s %10s\n", l.name.c_str(), l.meshComponents, l.normalMaps ? "yes" : "no",
                f2(l.vertexMeanMm).c_str(), f2(l.vertexP95Mm).c_str(), f2(l.vertexMaxMm).c_str(),
                f2(l.normalMeanDeg).c_str(), f2(l.cpuUsPerCharacter).c_str());
  std::printf("CPU: %s. GPU time per level is not measured here.\n", ladder.timedOn.c_str());
  const std::vector<std::string> problems = bake::ladderProblems(ladder);
  if (problems.empty()) {
    std::printf("The ladder is monotone: no level has a larger error than a cheaper one.\n");
  } else {
    std::printf("The ladder is NOT monotone (levels kept in their order):\n");
    for (const std::string& p : problems) std::printf("  %s\n", p.c_str());
  }

  if (!o.report.empty()) {
    const fs::path dir = o.report;
    fs::create_directories(dir);
    json frameList = json::array();
    for (size_t i = 0; i < frames.size(); ++i)
      frameList.push_back({{"clip", sources[frames[i].clip].file.filename().string()},
                           {"frame", frames[i].frame},
                           {"simulated", failures[i].empty()},
                           {"failure", failures[i]}});
    json report = {{"model", o.model},
                   {"truth", truth},
                   {"clips_are_the_models_own", ownClips},
                   {"frames", frameList},
                   {"quality_levels", bake::ladderReportJson(ladder)},
                   {"seconds", elapsed()}};
    writeTextFileAtomic(dir / "quality_levels.svg", bake::ladderPlotSvg(ladder));
    writeTextFileAtomic(dir / "levels.json", report.dump(2) + "\n");
    std::string md = "# `swish levels " + o.model + "`\n\n" + std::to_string(poses.size()) + " of " +
                     std::to_string(frames.size()) + " truth simulations succeeded (levels.json lists the frames and " +
                     "why a simulation failed).\n\n" + bake::ladderMarkdown(ladder, nullptr, "quality_levels.svg");
    writeTextFileAtomic(dir / "levels.md", md);
    std::printf("Wrote %s (levels.md, levels.json, quality_levels.svg).\n", dir.string().c_str());
  }
  runtime::storeLadder(model, ladder);
  if (out.has_parent_path()) fs::create_directories(out.parent_path());
  saveModel(model, out);
  std::printf("Wrote %s with the measured ladder in its metadata (\"%s\"), in %.1f s.\n", out.string().c_str(),
              runtime::kQualityLevelsKey, elapsed());
  return 0;
}

swish::cli::CommandRegistration reg{
    "levels", "Measure a baked model's quality levels against its source simulation and store them in the model",
    [](CLI::App& app) -> swish::cli::RunFn {
      auto o = std::make_shared<LevelsCliOptions>();
      app.add_option("model", o->model, "the .swish model (its bake metadata names the character and the clips)")
          ->required();
      app.add_option("--clips", o->clips,
                     "animation clips (BVH/glTF/FBX on the model's skeleton) to take the truth poses from; default: "
                     "the clips the model was baked from, as its metadata names them");
      app.add_option("--frames", o->frames,
                     "truth poses: frames evenly spaced over the clips (default 40; each costs a few seconds of CPU "
                     "for the default model's simulation)")
          ->check(CLI::Range(size_t(1), size_t(100000)));
      app.add_option("--every", o->every,
                     "take only every Mth frame of each clip (frames M, 2M, ...), then at most --frames of them, "
                     "evenly spaced")
          ->check(CLI::Range(size_t(1), size_t(100000)));
      app.add_option("--out", o->out, "write the model here instead of over MODEL (written atomically either way)");
      app.add_option("--report", o->report,
                     "also write levels.md, levels.json and quality_levels.svg (error against CPU time) into this "
                     "folder");
      swish::cli::addTruthOverrideOptions(app, o->truth, "the ladder's 'measured_on'");
      app.add_option("--threads", o->threads, "threads for the truth simulations (default 0: all cores)")
          ->check(CLI::Range(0, 1024));
      app.footer(
          "Each level of the model's ladder (its metadata's \"quality_levels\", else the default: all K "
          "components with normal maps, K/2 with maps, K/4 and K/8 with the mesh's own normals, the mean shape "
          "skinned) is measured against the truth: vertex error mean / p95 / max (mm) with the first k predicted "
          "weights, the normal-map error (deg) of what the renderer shades with at that level, and the run-time CPU "
          "time per character (MLP + novelty guard, + lookup with maps; median of batches of 22). A level with a "
          "larger error than a cheaper one is reported, not reordered. `swish bake` measures the same on its "
          "held-out poses itself (docs/baking.md, \"Quality levels\").\n\n"
          "Example: swish levels assets/default/default.swish --frames 40 --threads 2 --out /tmp/default_levels.swish "
          "--report /tmp/levels");
      return [o] { return runLevels(*o); };
    }};

}  // namespace
