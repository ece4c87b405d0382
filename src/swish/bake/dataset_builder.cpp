#include "swish/bake/dataset_builder.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "swish/bake/default_character.hpp"
#include "swish/bake/dataset_preview.hpp"
#include "swish/bake/pose_simulation.hpp"
#include "swish/bake/pose_thinning.hpp"
#include "swish/runtime/theta.hpp"
#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/io/character_import.hpp"
#include "swish/model/atomic_write.hpp"

namespace swish::bake {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// "simulation  40% (80/200)  12.0 s elapsed, about 18.0 s left" - the same shape for every long step.
std::string progressLine(const std::string& step, size_t done, size_t total, double elapsed, double left) {
  char line[256];
  std::snprintf(line, sizeof line, "part 1: %-10s %3.0f%% (%zu/%zu) %7.1f s elapsed, about %7.1f s left",
                step.c_str(), total ? 100.0 * double(done) / double(total) : 100.0, done, total, elapsed, left);
  return line;
}

// Throttles progress lines: at most one per `interval` seconds, plus the last one.
struct ProgressThrottle {
  double interval = 2.0;
  Clock::time_point last = Clock::now() - std::chrono::hours(1);
  bool due(size_t done, size_t total) {
    if (done < total && std::chrono::duration<double>(Clock::now() - last).count() < interval) return false;
    last = Clock::now();
    return true;
  }
};

std::string namingName(io::JointNaming n) { return io::jointNamingName(n); }

// A digest of the thinned pose list: a different list means different pose ids.
uint64_t poseListDigest(const std::vector<Pose>& poses) {
  Fnv1a f;
  for (const Pose& p : poses) {
    f.vec(p.local);
    f.matrix(p.rootTranslation);
  }
  return f.h;
}

// Deletes the dataset's pose files when they were made with other settings; returns true if it did.
bool resetDatasetIfStale(const fs::path& dir, const nlohmann::json& settings,
                         const std::function<void(const std::string&)>& log) {
  const fs::path marker = dir / "part1_settings.json";
  bool stale = false;
  if (fs::exists(marker)) {
    nlohmann::json old;
    try {
      old = nlohmann::json::parse(std::ifstream(marker));
    } catch (const nlohmann::json::exception&) {
      old = nullptr;  // unreadable: treat as other settings
    }
    stale = old != settings;
  } else {
    stale = fs::exists(dir / "poses") && !fs::is_empty(dir / "poses");  // poses of unknown settings
  }
  if (stale) {
    if (log) log("part 1: the dataset in " + dir.string() + " was made with other settings; rebuilding its poses");
    std::error_code ec;
    for (const char* sub : {"poses", "normal_maps"}) fs::remove_all(dir / sub, ec);
    for (const char* f : {"manifest.json", "character.bin"}) fs::remove(dir / f, ec);
  }
  fs::create_directories(dir);
  writeTextFileAtomic(marker, settings.dump(2));
  return stale;
}

}  // namespace

Character loadDatasetCharacter(const DatasetBuildSettings& s) {
  if (!s.characterFile.empty()) {
    io::CharacterImportOptions o;
    if (!s.bodyMeshNames.empty()) o.bodyNames = s.bodyMeshNames;
    if (!s.garmentMeshNames.empty()) o.garmentNames = s.garmentMeshNames;
    if (!s.simulationMeshNames.empty()) o.simulationMeshNames = s.simulationMeshNames;
    o.requiredJoints = s.inputJoints;
    return io::importCharacter(s.characterFile, o);
  }
  if (!s.characterRecipe.empty()) return makeDefaultCharacter(loadDefaultCharacterRecipe(s.characterRecipe));
  return makeDefaultCharacter();
}

PoseShapeSettings DatasetBuildSettings::poseShape() const {
  PoseShapeSettings p;
  p.simulationVertices = simulationVertices;
  p.simulation = simulation;
  p.limbClearance = limbClearance;
  p.transfer = transfer;
  return p;
}

nlohmann::json DatasetBuildSettings::toJson() const {
  nlohmann::json clipList = nlohmann::json::array();
  for (const ClipSource& c : clips) {
    nlohmann::json m = nlohmann::json::object();
    for (const auto& [a, b] : c.jointMap) m[a] = b;
    clipList.push_back({{"file", c.file.string()}, {"naming", namingName(c.naming)}, {"joint_map", m},
                        {"fps", c.framesPerSecond}});
  }
  const ClothSimSettings& m = simulation;
  return {
      {"character",
       {{"file", characterFile.string()}, {"recipe", characterRecipe.string()}, {"body_mesh", bodyMeshNames},
        {"garment_mesh", garmentMeshNames}, {"simulation_mesh", simulationMeshNames}}},
      {"clips", clipList},
      {"input_joints", inputJoints},
      {"sampling",
       {{"characters", sampling.characters}, {"seconds_per_character", sampling.secondsPerCharacter},
        {"sample_rate", sampling.sampleRate}, {"mirror_odd_characters", sampling.mirrorOddCharacters},
        {"speed_jitter", sampling.speedJitter}, {"seed", sampling.seed}}},
      {"thinning", {{"tolerance", thinningTolerance}, {"target_poses", targetPoses}, {"include_rest_pose", includeRestPose}}},
      {"simulation",
       {{"preset", m.material.name}, {"vertices", simulationVertices}, {"thickness", m.thickness},
        {"transition_seconds", m.transitionSeconds}, {"settle_seconds", m.settleSeconds},
        {"frame_rate", m.frameRate}, {"substeps", m.substeps}, {"iterations", m.iterations},
        {"equilibrium_tolerance", m.equilibriumTolerance}, {"equilibrium_seconds", m.equilibriumSeconds},
        {"equilibrium_iterations", m.equilibriumIterations}, {"retries", m.retries},
        {"final_projection", m.finalProjection},
        {"gravity", -m.gravity.y()}, {"limb_clearance", limbClearance.clearance}, {"attach_band", m.attachTopFraction}}},
      {"transfer",
       {{"smoothing_strength", transfer.smoothing.strength}, {"smoothing_iterations", transfer.smoothing.iterations},
        {"smoothing_weights", transfer.smoothing.weights == LaplacianWeights::Cotangent ? "cotangent" : "uniform"}}},
      {"normal_maps",
       {{"size", transfer.normalMap.width}, {"max_distance", transfer.normalMap.maxDistance},
        {"dilation_rings", transfer.normalMap.dilationRings}, {"bit_depth", normalMapBitDepth}}},
  };
}

nlohmann::json DatasetBuildResult::toJson() const {
  nlohmann::json f = nlohmann::json::array();
  for (const FailedPose& p : failed) f.push_back({{"pose", p.id}, {"reason", p.reason}});
  nlohmann::json st = nlohmann::json::array();
  for (const DatasetBuildStep& s : steps) st.push_back({{"step", s.name}, {"seconds", s.seconds}});
  return {{"clip_frames", clipFrames},     {"samples", samples},
          {"kept_poses", keptPoses},       {"rest_pose_added", restPoseAdded},
          {"tolerance", tolerance},
          {"poses_corrected", posesCorrected}, {"max_correction_degrees", maxCorrectionDegrees},
          {"max_correction_towards_rest", maxTowardsRest},
          {"simulation_vertices", simulationVertices},
          {"simulated", simulated},        {"simulations_reused", simulationsReused},
          {"transferred", transferred},    {"transfers_reused", transfersReused},
          {"failed", f},                   {"rebuilt", rebuilt},
          {"simulation", simulationReport},
          {"steps", st}};
}

// Clips -> pose samples -> thinned poses (+ the rest pose): the poses part 1 simulates, before limb
// clearance. Fills res's counts and steps.
std::vector<Pose> thinnedPoses(const DatasetBuildSettings& s, const Character& character,
                               const std::vector<uint32_t>& inputJoints, DatasetBuildResult& res,
                               const std::function<void(const std::string&)>& log) {
  auto step = [&](const std::string& name, Clock::time_point t) { res.steps.push_back({name, since(t)}); };
  auto t = Clock::now();
  std::vector<AnimationClip> clips;
  for (const ClipSource& c : s.clips) {
    io::AnimationImportOptions o;
    o.retarget.jointMap.naming = c.naming;
    o.retarget.jointMap.explicitPairs = c.jointMap;
    o.retarget.requiredJoints = s.inputJoints;
    o.framesPerSecond = c.framesPerSecond;
    clips.push_back(io::importAnimation(c.file, character.skeleton, o));
    res.clipFrames += clips.back().frames.size();
    log("part 1: clip " + c.file.string() + ": " + std::to_string(clips.back().frames.size()) + " frames at " +
        std::to_string(int(clips.back().framesPerSecond)) + " fps");
  }
  step("clips", t);

  // Poses: sample, thin, back to full-skeleton poses.
  t = Clock::now();
  PoseSamplingOptions so = s.sampling;
  so.joints = s.inputJoints;
  const PoseSamples samples = samplePoses(character.skeleton, clips, so);
  res.samples = samples.size();
  const ThinningResult thin =
      s.targetPoses > 0 ? thinPosesToCount(samples, s.targetPoses) : thinPoses(samples, s.thinningTolerance);
  res.tolerance = thin.tolerance;
  std::vector<Pose> poses;
  for (uint32_t k : thin.kept)
    poses.push_back(canonicalPose(character.skeleton, poseOfSample(character.skeleton, clips, samples.origins[k])));
  {
    char line[200];
    std::snprintf(line, sizeof line, "part 1: %zu samples thinned to %zu poses (tolerance %.4f, %d passes) in %.2f s",
                  res.samples, poses.size(), double(thin.tolerance), thin.passes, since(t));
    log(line);
  }
  if (s.includeRestPose) {
    const Pose rest = canonicalPose(character.skeleton, character.skeleton.restPose());
    const float nearest = nearestKeptDistance(samples, thin.kept, runtime::computeTheta(inputJoints, rest.local));
    if (nearest > thin.tolerance) {
      poses.push_back(rest);
      res.restPoseAdded = true;
    }
    char line[200];
    std::snprintf(line, sizeof line, "part 1: the rest pose is %.4f from the nearest kept pose: ", double(nearest));
    log(line + (res.restPoseAdded ? "added as pose " + std::to_string(poses.size() - 1) : std::string("already covered")));
  }
  res.keptPoses = poses.size();
  step("sampling + thinning", t);
  return poses;
}

DatasetBuildResult buildDataset(const DatasetBuildSettings& s, const fs::path& datasetDir, const fs::path& simulationDir,
                                const fs::path& previewDir, const std::function<void(const std::string&)>& logFn) {
  auto log = [&](const std::string& line) {
    if (logFn) logFn(line);
  };
  DatasetBuildResult res;
  auto step = [&](const std::string& name, Clock::time_point t) { res.steps.push_back({name, since(t)}); };
  if (s.clips.empty()) throw Error("bake part 1: no animation clips");
  if ((s.thinningTolerance > 0.f) == (s.targetPoses > 0))
    throw Error("bake part 1: give exactly one of a thinning tolerance and a target pose count");
  s.simulation.validate();

  // Character and clips.
  auto t = Clock::now();
  const Character character = loadDatasetCharacter(s);
  std::vector<uint32_t> inputJoints;
  for (const std::string& name : s.inputJoints) {
    const int j = character.skeleton.find(name);
    if (j < 0) throw Error("bake part 1: input joint '" + name + "' is not in character '" + character.name + "'");
    inputJoints.push_back(uint32_t(j));
  }
  for (const std::string& name : s.alsoRequiredJoints)
    if (character.skeleton.find(name) < 0)
      throw Error("bake: train.input_joints: joint '" + name + "' is not in character '" + character.name + "'");
  log("part 1: character '" + character.name + "': " + std::to_string(character.skeleton.size()) + " joints, body " +
      std::to_string(character.body.vertexCount()) + " vertices, game mesh " +
      std::to_string(character.garment.vertexCount()) + " vertices");
  step("character", t);

  std::vector<Pose> poses = thinnedPoses(s, character, inputJoints, res, log);

  // Clearance, simulation and transfer of one pose are PoseShapeSimulator's steps (pose_shape.hpp),
  // shared with `swish replay --truth-every`; here each step runs over all poses in turn.
  t = Clock::now();
  const PoseShapeSimulator shapes(character, s.poseShape());
  step("simulation setup", t);

  // Limbs out of the trunk: the corrected poses are simulated; the dataset keeps the recorded poses,
  // which are what the model sees at run time (see the transfer below).
  const std::vector<Pose> recorded = poses;
  if (shapes.clearance()) {
    t = Clock::now();
    const LimbClearance& clearance = *shapes.clearance();
    std::vector<std::vector<LimbCorrection>> corrections(poses.size());
    tbb::parallel_for(size_t(0), poses.size(),
                      [&](size_t i) { poses[i] = shapes.poseToSimulate(recorded[i], &corrections[i]); });
    size_t stillInside = 0;
    for (const auto& c : corrections) {
      if (!c.empty()) ++res.posesCorrected;
      for (const LimbCorrection& x : c) {
        res.maxCorrectionDegrees = std::max(res.maxCorrectionDegrees, x.degrees);
        if (x.depthAfter > 0.f) ++stillInside;
      }
    }
    if (!clearance.skipped().empty()) log("part 1: limb clearance skipped: " + clearance.skipped());
    char line[240];
    if (clearance.limbCount() > 0) std::snprintf(line, sizeof line,
                  "part 1: limb clearance %.0f mm: %zu of %zu poses had a limb in the trunk (%zu limbs of the body "
                  "checked); turned out by up to %.0f degrees, %zu limbs still inside, in %.2f s",
                  1000.0 * s.limbClearance.clearance, res.posesCorrected, poses.size(), clearance.limbCount(),
                  double(res.maxCorrectionDegrees), stillInside, since(t));
    if (clearance.limbCount() > 0) log(line);
    if (clearance.checksHead()) {
      for (const auto& c : corrections)
        for (const LimbCorrection& x : c) res.maxTowardsRest = std::max(res.maxTowardsRest, x.towardsRest);
      std::snprintf(line, sizeof line,
                    "part 1: head clearance (one-surface body, %zu head vertices checked): %zu of %zu poses had the "
                    "head inside the body; neck turned back towards rest by up to %.0f %% (%.0f degrees), %zu still "
                    "inside, in %.2f s",
                    clearance.headVertexCount(), res.posesCorrected, poses.size(), 100.0 * res.maxTowardsRest,
                    double(res.maxCorrectionDegrees), stillInside, since(t));
      log(line);
      for (size_t i = 0; i < corrections.size(); ++i)
        for (const LimbCorrection& x : corrections[i]) {
          std::snprintf(line, sizeof line,
                        "part 1: head clearance: pose %zu: head %.1f mm inside, neck turned %.0f %% back to rest "
                        "(%s %.1f degrees), %.1f mm after",
                        i, 1000.0 * x.depthBefore, 100.0 * x.towardsRest, x.joint.c_str(), double(x.degrees),
                        1000.0 * x.depthAfter);
          log(line);
        }
    }
    step("limb clearance", t);
  }

  // Dataset folder: reset when its poses were made with other settings or another pose list.
  nlohmann::json settingsJson = s.toJson();
  settingsJson["pose_list_digest"] = std::to_string(poseListDigest(poses));
  settingsJson["kept_poses"] = poses.size();
  settingsJson["thinning_tolerance_used"] = res.tolerance;
  // Part 2 keeps this pose in its training split (bake_training.cpp); -1: none was added.
  settingsJson["rest_pose_id"] = res.restPoseAdded ? int64_t(poses.size() - 1) : int64_t(-1);
  res.rebuilt = resetDatasetIfStale(datasetDir, settingsJson, logFn);
  const DatasetWriter writer(datasetDir, character, inputJoints, settingsJson, s.normalMapBitDepth);

  // Simulation (resumable per pose; failures are recorded in their files and left out).
  t = Clock::now();
  const ClothSolver& solver = shapes.solver();
  res.simulationVertices = solver.mesh().vertexCount();
  log("part 1: simulation mesh " + std::to_string(res.simulationVertices) + " vertices, " +
      std::to_string(solver.mesh().triangles.rows()) + " triangles, preset '" + s.simulation.material.name + "'");
  ProgressThrottle simThrottle;
  const auto simStart = Clock::now();
  const PoseSimulationRun sim = simulatePoses(
      solver, poses, simulationDir,
      [&](size_t done, size_t total, double left) {
        if (simThrottle.due(done, total)) log(progressLine("simulation", done, total, since(simStart), left));
        return true;
      },
      s.threads);
  res.simulated = sim.simulated;
  res.simulationsReused = sim.reused;
  for (const auto& [id, reason] : sim.failures) {
    res.failed.push_back({id, "simulation: " + reason});
    log("part 1: pose " + std::to_string(id) + " left out: simulation failed: " + reason);
  }
  step("simulation", t);

  // Transfer + smoothing + normal map per pose, in parallel, each pose written when done.
  t = Clock::now();
  std::vector<uint32_t> todo;
  for (uint32_t id = 0; id < poses.size(); ++id) {
    const bool failed = std::any_of(sim.failures.begin(), sim.failures.end(), [&](const auto& f) { return f.first == id; });
    if (failed) continue;
    if (writer.hasPose(id))
      ++res.transfersReused;
    else
      todo.push_back(id);
  }
  std::mutex mutex;
  std::atomic<size_t> done{0};
  ProgressThrottle transferThrottle;
  const auto transferStart = Clock::now();
  const size_t total = todo.size();
  auto one = [&](size_t k) {
    const uint32_t id = todo[k];
    std::string failure;
    try {
      const auto rec = loadFinishedPose(simulationDir, id, poseFingerprint(solver, poses[id]));
      if (!rec || !rec->result.ok) {
        failure = "simulation result missing or not usable";
      } else {
        // The pre-skin shape from the corrected simulation, the world shape skinned with the
        // recorded pose (pose_shape.hpp); the dataset keeps the recorded pose.
        TransferredPose tp = shapes.gameMeshShape(poses[id], recorded[id], rec->result.positions);
        DatasetPose dp;
        dp.id = id;
        dp.pose = recorded[id];
        dp.gameMeshWorld = std::move(tp.gameMeshWorld);
        dp.gameMeshPreSkin = std::move(tp.gameMeshPreSkin);
        dp.normalMap = std::move(tp.normalMap);
        dp.residuals = rec->result.residuals;
        writer.writePose(dp);
      }
    } catch (const Error& e) {
      failure = std::string("transfer: ") + e.what();
    }
    std::lock_guard<std::mutex> lock(mutex);
    const size_t n = ++done;
    if (!failure.empty()) {
      res.failed.push_back({id, failure});
      log("part 1: pose " + std::to_string(id) + " left out: " + failure);
    } else {
      ++res.transferred;
    }
    if (transferThrottle.due(n, total)) {
      const double el = since(transferStart);
      log(progressLine("transfer", n, total, el, el / double(n) * double(total - n)));
    }
  };
  if (s.threads > 0) {
    tbb::task_arena arena(s.threads);
    arena.execute([&] { tbb::parallel_for(size_t(0), total, size_t(1), one); });
  } else {
    tbb::parallel_for(size_t(0), total, size_t(1), one);
  }
  std::sort(res.failed.begin(), res.failed.end(), [](const FailedPose& a, const FailedPose& b) { return a.id < b.id; });
  nlohmann::json source = {{"tool", "swish bake (part 1)"}, {"samples", res.samples}, {"kept_poses", res.keptPoses},
                           {"simulation_vertices", res.simulationVertices}};
  writer.writeManifest(res.failed, source);
  step("transfer + normal maps", t);

  // The simulation's own figures: failures per reason, retries, residuals, seconds per pose per core;
  // convergence and noise on a seeded sample of the kept poses (cached beside the simulations).
  {
    std::vector<std::pair<uint32_t, std::string>> transferFailures;
    for (const FailedPose& f : res.failed)
      if (f.reason.rfind("transfer", 0) == 0 || f.reason.rfind("simulation result", 0) == 0)
        transferFailures.push_back({f.id, f.reason});
    res.simulationReport = simulationRunJson(sim.poses, s.simulation, transferFailures);
    for (const SimulatedPoseSummary& p : sim.poses)
      if (p.attempts > 1)
        log("part 1: pose " + std::to_string(p.id) + " needed " + std::to_string(p.attempts) + " attempts (" +
            (p.ok ? "kept" : "left out") + "); first attempt: " + p.firstFailure);
    if (s.quality.poses > 0) {
      t = Clock::now();
      std::vector<uint32_t> okIds;
      for (const SimulatedPoseSummary& p : sim.poses)
        if (p.ok) okIds.push_back(p.id);
      const std::vector<uint32_t> ids = sampleQualityPoses(okIds, s.quality.poses, s.quality.seed);
      const uint64_t fp = simulationQualityFingerprint(solver, poses, ids, s.quality);
      const fs::path cache = simulationDir / "quality.json";
      nlohmann::json quality;
      try {
        if (fs::exists(cache)) {
          nlohmann::json old = nlohmann::json::parse(std::ifstream(cache));
          if (old.value("fingerprint", std::string()) == std::to_string(fp)) quality = old.at("quality");
        }
      } catch (const std::exception&) {
        quality = nullptr;  // unreadable: measured again
      }
      if (quality.is_null()) {
        std::vector<Points3f> shapes;
        for (uint32_t id : ids) {
          const auto rec = loadFinishedPose(simulationDir, id, poseFingerprint(solver, poses[id]));
          shapes.push_back(rec ? rec->result.positions : Points3f());
        }
        SimulationQualitySettings qs = s.quality;
        qs.threads = s.threads;
        log("part 1: measuring the simulation's convergence and noise on " + std::to_string(ids.size()) + " poses");
        ProgressThrottle qThrottle;
        const SimulationQuality q = measureSimulationQuality(character, solver, poses, ids, shapes, qs,
                                                             [&](const std::string& line) {
                                                               if (qThrottle.due(0, 1)) log("part 1: " + line);
                                                             });
        quality = q.toJson();
        writeTextFileAtomic(cache, nlohmann::json{{"fingerprint", std::to_string(fp)}, {"quality", quality}}.dump(2) + "\n");
      }
      res.simulationReport["quality"] = quality;
      char line[256];
      std::snprintf(line, sizeof line,
                    "part 1: simulation convergence (2x substeps, half the tolerance) %.2f mm mean, %.2f mm p95; "
                    "noise (%.0f degree turns) %.2f mm mean, %.2f mm p95",
                    quality.value("convergence_mean_mm", 0.0), quality.value("convergence_p95_mm", 0.0),
                    quality.value("noise_turn_degrees", 0.0), quality.value("noise_mean_mm", 0.0),
                    quality.value("noise_p95_mm", 0.0));
      log(line);
      step("simulation quality", t);
    }
    char line[200];
    std::snprintf(line, sizeof line, "part 1: %.2f s per pose per core; %zu poses retried",
                  res.simulationReport.value("seconds_per_pose_per_core", 0.0),
                  size_t(res.simulationReport.value("retried_poses", 0)));
    log(line);
  }
  if (res.transferred + res.transfersReused == 0)
    throw Error("bake part 1: every pose failed; nothing to train on (see the failures above)");

  // Preview images of a few poses, for a person to look at.
  if (!previewDir.empty() && s.previewPoses > 0) {
    t = Clock::now();
    const Dataset ds = readDataset(datasetDir);
    res.previews = writeDatasetPreview(ds, previewDir, s.previewPoses, s.previewSize);
    log("part 1: " + std::to_string(res.previews.size()) + " preview files in " + previewDir.string());
    step("preview", t);
  }
  return res;
}

nlohmann::json checkSimulation(const DatasetBuildSettings& s, size_t poseCount, uint64_t seed,
                               const std::function<void(const std::string&)>& logFn) {
  auto log = [&](const std::string& line) {
    if (logFn) logFn(line);
  };
  const auto start = Clock::now();
  if (s.clips.empty()) throw Error("simulation check: no animation clips");
  if ((s.thinningTolerance > 0.f) == (s.targetPoses > 0))
    throw Error("simulation check: give exactly one of a thinning tolerance and a target pose count");
  s.simulation.validate();
  const Character character = loadDatasetCharacter(s);
  std::vector<uint32_t> inputJoints;
  for (const std::string& name : s.inputJoints) {
    const int j = character.skeleton.find(name);
    if (j < 0) throw Error("simulation check: input joint '" + name + "' is not in character '" + character.name + "'");
    inputJoints.push_back(uint32_t(j));
  }
  DatasetBuildResult res;
  const std::vector<Pose> all = thinnedPoses(s, character, inputJoints, res, log);
  std::vector<uint32_t> every(all.size());
  for (uint32_t i = 0; i < every.size(); ++i) every[i] = i;
  const std::vector<uint32_t> ids = sampleQualityPoses(every, poseCount, seed);
  const PoseShapeSimulator shapes(character, s.poseShape());
  const ClothSolver& solver = shapes.solver();
  log("simulation check: " + std::to_string(ids.size()) + " of the " + std::to_string(all.size()) +
      " thinned poses (seed " + std::to_string(seed) + "), " + std::to_string(solver.mesh().vertexCount()) +
      " simulation vertices, preset '" + s.simulation.material.name + "'");

  // The poses as the bake would simulate them (limbs out of the trunk), one solve per pose.
  std::vector<Pose> poses(all.size());
  std::vector<PoseSimulation> results(ids.size());
  std::mutex mutex;
  size_t done = 0;
  ProgressThrottle throttle;
  const auto simStart = Clock::now();
  auto one = [&](size_t k) {
    const uint32_t id = ids[k];
    poses[id] = shapes.poseToSimulate(all[id]);
    results[k] = solver.simulate(poses[id]);
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (!results[k].ok) log("simulation check: pose " + std::to_string(id) + " failed: " + results[k].failure);
    else if (results[k].attempts > 1)
      log("simulation check: pose " + std::to_string(id) + " kept after a retry; first attempt: " + results[k].firstFailure);
    if (throttle.due(done, ids.size())) {
      const double el = since(simStart);
      log(progressLine("simulation", done, ids.size(), el, el / double(done) * double(ids.size() - done)));
    }
  };
  if (s.threads > 0) {
    tbb::task_arena arena(s.threads);
    arena.execute([&] { tbb::parallel_for(size_t(0), ids.size(), size_t(1), one); });
  } else {
    tbb::parallel_for(size_t(0), ids.size(), size_t(1), one);
  }
  std::vector<SimulatedPoseSummary> summaries;
  std::vector<uint32_t> okIds;
  for (size_t k = 0; k < ids.size(); ++k) {
    const PoseSimulation& r = results[k];
    summaries.push_back({ids[k], r.ok, r.failure, r.attempts, r.firstFailure, r.residuals});
    if (r.ok) okIds.push_back(ids[k]);
  }
  nlohmann::json out = {{"tool", "swish bake --check-simulation"},
                        {"character", character.name},
                        {"thinned_poses", all.size()},
                        {"sampled_poses", ids},
                        {"seed", seed},
                        {"simulation_vertices", solver.mesh().vertexCount()},
                        {"settings", s.toJson()["simulation"]},
                        {"simulation", simulationRunJson(summaries, s.simulation)}};
  nlohmann::json failures = nlohmann::json::array();
  for (const SimulatedPoseSummary& p : summaries)
    if (!p.ok) failures.push_back({{"pose", p.id}, {"reason", p.failure}});
  out["simulation"]["failures"] = failures;
  if (s.quality.poses > 0 && !okIds.empty()) {
    const std::vector<uint32_t> q = sampleQualityPoses(okIds, s.quality.poses, seed);
    std::vector<Points3f> qShapes;
    for (uint32_t id : q)
      for (size_t k = 0; k < ids.size(); ++k)
        if (ids[k] == id) qShapes.push_back(results[k].positions);
    SimulationQualitySettings qs = s.quality;
    qs.threads = s.threads;
    qs.seed = seed;
    log("simulation check: convergence and noise on " + std::to_string(q.size()) + " poses (3 solves each)");
    ProgressThrottle qThrottle;
    out["simulation"]["quality"] = measureSimulationQuality(character, solver, poses, q, qShapes, qs, [&](const std::string& l) {
                                     if (qThrottle.due(0, 1)) log(l);
                                   }).toJson();
  }
  out["seconds"] = since(start);
  return out;
}

}  // namespace swish::bake
