#include "swish/bake/pipeline/bake_pipeline.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>

#include <optional>
#include <set>

#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/bake/poses/clip_list.hpp"
#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/bake/report/bake_report.hpp"
#include "swish/bake/report/subject_evaluation.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/file_lock.hpp"
#include "swish/files/json_file.hpp"
#include "swish/model/model_file.hpp"

namespace swish::bake {

namespace {
using Clock = std::chrono::steady_clock;

// The dataset's content and the train settings. The manifest's per-pose solve times are left out: they
// are measurements of the run that made the dataset, not content, and would make the model's bytes
// differ between two bakes of the same recipe (another machine, another load, a cluster's nodes).
std::string manifestContent(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string manifest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    nlohmann::json m = nlohmann::json::parse(manifest);
    if (m.contains("poses") && m["poses"].is_array())
      for (auto& p : m["poses"])
        if (p.is_object() && p.contains("residuals") && p["residuals"].is_object()) p["residuals"].erase("seconds");
    return m.dump();
  } catch (const nlohmann::json::exception&) {
    return manifest;  // not JSON: hashed as it is (reading the dataset reports the problem)
  }
}

std::string fingerprint(const BakeConfig& cfg) {
  std::string manifest = manifestContent(cfg.dataset / "manifest.json");
  if (cfg.part1 && !cfg.part1->holdoutSubjects.empty())  // the held-out subjects' dataset is evaluated too
    manifest += manifestContent(cfg.holdoutDatasetDir() / "manifest.json");
  if (cfg.simulatesAnchorFrames())  // the body anchors are fitted on the frames as played
    manifest += manifestContent(cfg.anchorFramesDatasetDir() / "manifest.json");
  return std::to_string(std::hash<std::string>{}(manifest)) + "/" + cfg.train.toJson().dump();
}

// The model file already holds the result of this dataset + settings?
bool part2Current(const BakeConfig& cfg) {
  if (!std::filesystem::exists(cfg.modelPath()) || !std::filesystem::exists(cfg.reportDir() / "report.json"))
    return false;
  try {
    const Model m = loadModel(cfg.modelPath());
    const auto meta = nlohmann::json::parse(m.metadata);
    return meta.value("bake_fingerprint", std::string()) == fingerprint(cfg);
  } catch (const std::exception&) {
    return false;  // unreadable or foreign: bake again
  }
}
}  // namespace

std::pair<DatasetBuildSettings, DatasetBuildSettings> splitHeldOutSubjects(const DatasetBuildSettings& s) {
  DatasetBuildSettings training = s, heldOut = s;
  training.clips.clear();
  heldOut.clips.clear();
  std::set<std::string> held;
  for (const auto& subject : s.holdoutSubjects) held.insert(normaliseSubject(subject));
  for (const ClipSource& c : s.clips) (held.count(normaliseSubject(c.subject)) ? heldOut : training).clips.push_back(c);
  if (held.empty()) return {training, heldOut};
  if (training.clips.empty())
    throw Error("bake part 1: part1.holdout holds out every clip: nothing is left to train on");
  return {training, framesAsPlayed(heldOut, s.holdoutPoses)};
}

DatasetBuildSettings framesAsPlayed(DatasetBuildSettings s, size_t count) {
  // Frames as a game plays them, one character, unmirrored; nothing added, nothing previewed.
  s.evenPoses = count;
  s.includeRestPose = false;
  s.previewPoses = 0;
  s.sampling.characters = 1;
  s.sampling.mirrorOddCharacters = false;
  s.simulatedPoseList = {};  // a cluster's pose list is the training poses'
  return s;
}

std::vector<Pose> anchorFramesAsPlayed(const BakeConfig& cfg, const Skeleton& skeleton,
                                       const std::function<void(const std::string&)>& log,
                                       std::vector<std::string>* clipOf) {
  if (!cfg.train.anchorsAsPlayed) return {};
  if (!cfg.part1) throw Error("bake: train.anchor_poses \"as_played\" reads part1.clips; the recipe has no part1");
  const auto t = Clock::now();
  const DatasetBuildSettings training = splitHeldOutSubjects(*cfg.part1).first;
  const std::vector<AnimationClip> clips =
      importClips(training.clips, skeleton, training.inputJoints, training.threads);
  const PoseSamples frames = evenlySpacedFrames(clips, cfg.train.anchorFramesAsPlayed);
  std::vector<Pose> poses;
  for (const PoseSamples::Origin& o : frames.origins) {
    poses.push_back(canonicalPose(skeleton, poseOfSample(skeleton, clips, o)));
    if (clipOf) clipOf->push_back(training.clips[o.clip].file.filename().string());
  }
  if (log) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "part 2: %zu frames as played, spread over the %zu training clips, for the body anchors (%.1f s)",
                  poses.size(), clips.size(), std::chrono::duration<double>(Clock::now() - t).count());
    log(line);
  }
  return poses;
}

DatasetBuildSettings bakeTrainingSettings(const BakeConfig& cfg) {
  if (!cfg.part1) throw Error("bake: the config has no part1 section");
  DatasetBuildSettings s = splitHeldOutSubjects(*cfg.part1).first;
  s.alsoRequiredJoints = cfg.train.inputJoints;  // checked before any simulation
  return s;
}

BakeRunResult runBake(const BakeConfig& cfg, const BakeRunOptions& opt) {
  const auto t0 = Clock::now();
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  BakeRunResult res;
  res.model = cfg.modelPath();
  res.report = cfg.reportDir() / "report.md";

  // Part 1: the dataset folder (resumable: finished simulations and poses are kept).
  if (cfg.part1 && opt.part1) {
    const auto t1 = Clock::now();
    // One part 1 at a time per work folder: two bakes that share it (part 2 variants of one dataset)
    // would otherwise both walk part 1 and rewrite its manifest and pose files at once. The second
    // waits, then finds the first's poses done; part 2s run side by side.
    std::filesystem::create_directories(cfg.work);
    const std::filesystem::path lockFile = cfg.work / "part1.lock";
    const FileLock part1Lock =
        FileLock::acquire(lockFile, "swish bake '" + cfg.name + "', part 1", [&](const std::string& holder) {
          log("part 1: waiting for " + holder + ", which holds " + lockFile.string());
        });
    if (!part1Lock.held()) log("part 1: " + part1Lock.unsupportedReason() + "; going on without the lock");
    log("part 1: building the dataset " + cfg.dataset.string());
    DatasetBuildSettings part1Settings = *cfg.part1;
    part1Settings.alsoRequiredJoints = cfg.train.inputJoints;  // checked before any simulation
    part1Settings.simulatedPoseList = opt.simulatedPoseList;
    const auto [training, heldOut] = splitHeldOutSubjects(part1Settings);
    const DatasetBuildResult part1 =
        buildDataset(training, cfg.dataset, cfg.simulationDir(), cfg.previewDir(), opt.log);
    if (!heldOut.clips.empty()) {
      log("part 1: the held-out subjects' frames: " + std::to_string(heldOut.clips.size()) + " clips -> " +
          cfg.holdoutDatasetDir().string());
      const DatasetBuildResult h =
          buildDataset(heldOut, cfg.holdoutDatasetDir(), cfg.holdoutSimulationDir(), {}, opt.log);
      res.holdoutPart1 = h.toJson();
    }
    nlohmann::json anchorFramesPart1;
    if (cfg.simulatesAnchorFrames()) {
      // train.anchor_poses "as_played", "simulated": the training clips' frames as played, for the anchors.
      log("part 1: about " + std::to_string(cfg.train.anchorFramesAsPlayed) +
          " frames as played of the training clips, for the body anchors -> " + cfg.anchorFramesDatasetDir().string());
      const DatasetBuildResult a =
          buildDataset(framesAsPlayed(training, cfg.train.anchorFramesAsPlayed), cfg.anchorFramesDatasetDir(),
                       cfg.anchorFramesSimulationDir(), {}, opt.log);
      anchorFramesPart1 = a.toJson();
    }
    res.part1Seconds = std::chrono::duration<double>(Clock::now() - t1).count();
    res.part1 = part1.toJson();
    res.part1["seconds"] = res.part1Seconds;
    if (!res.holdoutPart1.is_null()) res.part1["held_out_subjects"] = res.holdoutPart1;
    if (!anchorFramesPart1.is_null()) res.part1["anchor_frames"] = anchorFramesPart1;
    std::filesystem::create_directories(cfg.reportDir());
    writeTextFileAtomic(cfg.reportDir() / "part1.json", res.part1.dump(2) + "\n");
    char line[256];
    std::snprintf(line, sizeof line, "part 1: done in %.1f s: %zu poses in the dataset, %zu left out", res.part1Seconds,
                  part1.transferred + part1.transfersReused, part1.failed.size());
    log(line);
  } else if (!std::filesystem::exists(cfg.dataset / "manifest.json")) {
    if (cfg.part1)
      throw Error("bake '" + cfg.name + "': no dataset at " + cfg.dataset.string() +
                  " (no manifest.json): part 1 has not run");
    throw Error("bake '" + cfg.name + "': no dataset at " + cfg.dataset.string() +
                " (no manifest.json) and no \"part1\" section to make one");
  } else if (cfg.part1) {
    log("part 1: not run here; using the dataset " + cfg.dataset.string() + " as it is");
  } else {
    log("part 1: no \"part1\" section; using the dataset " + cfg.dataset.string() + " as it is");
  }
  if (!opt.part2) {
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
  }

  // Part 2.
  if (!opt.force && part2Current(cfg)) {
    res.part2Skipped = true;
    log("part 2: " + res.model.string() + " is current (same dataset and settings); use --force to re-train");
    return res;
  }
  log("part 2: reading the dataset");
  const Dataset ds = readDataset(cfg.dataset);
  log("part 2: " + std::to_string(ds.poses.size()) + " poses, " + std::to_string(ds.character.garment.vertexCount()) +
      " game-mesh vertices");
  // The body anchors' frames as played (train.anchor_poses): simulated by part 1, or their nearest training poses.
  std::optional<Dataset> anchorFrameShapes;
  if (cfg.simulatesAnchorFrames()) {
    if (!std::filesystem::exists(cfg.anchorFramesDatasetDir() / "manifest.json"))
      throw Error("bake '" + cfg.name +
                  "': train.anchor_poses simulates frames as played, and there is no dataset of them at " +
                  cfg.anchorFramesDatasetDir().string() + " (no manifest.json): run part 1 with this recipe");
    anchorFrameShapes = readDataset(cfg.anchorFramesDatasetDir());
    log("part 2: " + std::to_string(anchorFrameShapes->poses.size()) +
        " simulated frames as played for the body anchors");
  }
  const std::vector<Pose> anchorFrames =
      cfg.simulatesAnchorFrames() ? std::vector<Pose>{} : anchorFramesAsPlayed(cfg, ds.character.skeleton, log);
  const auto t2 = Clock::now();
  const BakeProgress progress = [&](const std::string& stage, double f) {
    const double el = std::chrono::duration<double>(Clock::now() - t2).count();
    char line[256];
    if (f > 0.0 && f < 1.0)
      std::snprintf(line, sizeof line, "part 2: %3.0f%% %-32s %6.1f s elapsed, about %6.1f s left", 100.0 * f,
                    stage.c_str(), el, el / f - el);
    else
      std::snprintf(line, sizeof line, "part 2: %3.0f%% %-32s %6.1f s elapsed", 100.0 * f, stage.c_str(), el);
    log(line);
  };
  BakeTrainOutput out =
      trainBake(ds, cfg.train, progress, anchorFrames, anchorFrameShapes ? &*anchorFrameShapes : nullptr);
  if (out.ladder.measured()) {
    std::string line = "part 2: quality levels on the held-out poses (vertex mean mm, CPU us per character):";
    char item[96];
    for (const runtime::QualityLevel& l : out.ladder.levels) {
      std::snprintf(item, sizeof item, " %s %.2f / %.1f;", l.name.c_str(), l.vertexMeanMm, l.cpuUsPerCharacter);
      line += item;
    }
    const size_t problems = ladderProblems(out.ladder).size();
    log(line +
        (problems ? " NOT monotone (" + std::to_string(problems) + " pairs; report.md says which)" : " monotone"));
  }
  std::optional<SubjectEvaluation> subjects;
  if (cfg.part1 && !cfg.part1->holdoutSubjects.empty()) {
    log("part 2: evaluating on the held-out subjects' dataset " + cfg.holdoutDatasetDir().string());
    const Dataset holdout = readDataset(cfg.holdoutDatasetDir());
    const nlohmann::json origins = readJsonFile(cfg.holdoutDatasetDir() / "pose_origins.json", "pose origins");
    subjects = evaluateHeldOutSubjects(out, ds, holdout, origins, cfg.part1->holdoutSubjects, cfg.part1->holdoutPoses);
    char line[256];
    std::snprintf(line, sizeof line,
                  "part 2: held-out subjects: %zu poses, vertex error mean %.2f mm, p95 %.2f mm (rest shape skinned "
                  "%.2f / %.2f mm); random held-out frames of training clips %.2f / %.2f mm",
                  subjects->overall.poses, subjects->overall.totalMm.mean, subjects->overall.totalMm.p95,
                  subjects->overall.restSkinnedMm.mean, subjects->overall.restSkinnedMm.p95,
                  out.evaluation.totalMm.mean, out.evaluation.totalMm.p95);
    log(line);
    if (out.metadata.contains("distill")) {
      std::vector<const DatasetPose*> heldPoses;
      for (const DatasetPose& p : holdout.poses) heldPoses.push_back(&p);
      const TeacherComparison c = compareTeacher(out, heldPoses);
      out.metadata["distill"]["held_out_subjects_pre_skin_mean_mm"] = {
          {"poses", c.poses}, {"teacher", c.teacherMm}, {"network", c.networkMm}};
      std::snprintf(line, sizeof line,
                    "part 2: held-out subjects, pre-skinning mean through the mesh PCA: distillation teacher %.2f mm, "
                    "network %.2f mm",
                    c.teacherMm, c.networkMm);
      log(line);
    }
    const BakeEvaluation& o = subjects->overall;
    if (o.penetrationMeasured && o.pushOut) {
      std::snprintf(line, sizeof line,
                    "part 2: held-out subjects with the push-out: vertex error mean %.2f mm, p95 %.2f mm; garment "
                    "vertices inside the body %.1f %% (model %.1f %%, truth %.1f %%)",
                    o.totalPushedMm.mean, o.totalPushedMm.p95, 100.0 * o.pushedPenetration.share(),
                    100.0 * o.modelPenetration.share(), 100.0 * o.truthPenetration.share());
      log(line);
    }
  }
  Model model = out.model;
  nlohmann::json meta = nlohmann::json::parse(model.metadata);
  // The novelty guard as measured best on the held-out subjects (no subjects: the clamp alone).
  if (subjects && !subjects->guard.rows.empty()) {
    const GuardSetting& chosen = subjects->guard.rows[subjects->guard.chosen].setting;
    NoveltyGuard& g = model.noveltyGuard;
    if (!chosen.clamp) g.weightMin = g.weightMax = VecXf();
    g.blendStart = float(chosen.start);
    g.blendEnd = float(chosen.end);
    if (g.blends()) g.flagAbove = g.blendStart;
    meta["novelty_guard"]["clamp"] = chosen.clamp;
    meta["novelty_guard"]["blend"] = g.blends();
    meta["novelty_guard"]["blend_start"] = g.blendStart;
    meta["novelty_guard"]["blend_end"] = g.blendEnd;
    meta["novelty_guard"]["chosen_on"] = "held-out subjects: " + chosen.name();
    log("part 2: novelty guard: " + chosen.name() + " (the lowest mean error on the held-out subjects)");
  }
  meta["novelty_guard"]["flag_above"] = model.noveltyGuard.flagAbove;
  if (subjects) meta["errors"]["held_out_subjects"] = subjects->toJson();
  if (out.metadata.contains("distill")) meta["distill"] = out.metadata["distill"];  // with the subjects' comparison
  meta["bake_fingerprint"] = fingerprint(cfg);
  meta["name"] = cfg.name;
  model.metadata = meta.dump();
  std::filesystem::create_directories(cfg.output);
  writeBakeReport(out, ds, cfg.reportDir(), 4, subjects ? &*subjects : nullptr);
  saveModel(model, cfg.modelPath());  // last: its presence marks part 2 done
  res.part2Seconds = std::chrono::duration<double>(Clock::now() - t2).count();
  res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  char line[256];
  std::snprintf(line, sizeof line,
                "done in %.1f s: model %s, report %s; held-out vertex error mean %.2f mm, p95 %.2f mm", res.seconds,
                res.model.string().c_str(), res.report.string().c_str(), out.evaluation.totalMm.mean,
                out.evaluation.totalMm.p95);
  log(line);
  return res;
}

}  // namespace swish::bake
