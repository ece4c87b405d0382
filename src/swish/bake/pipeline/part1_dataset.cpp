#include "swish/bake/pipeline/part1_dataset.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/pose_driver.hpp"
#include "swish/bake/dataset/dataset_preview.hpp"
#include "swish/bake/poses/pose_thinning.hpp"
#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/core/skinning.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/io/character_import.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// "simulation  40% (80/200)  12.0 s elapsed, about 18.0 s left" - the same shape for every long step.
std::string progressLine(const std::string& step, size_t done, size_t total, double elapsed, double left) {
  char line[256];
  std::snprintf(line, sizeof line, "part 1: %-10s %3.0f%% (%zu/%zu) %7.1f s elapsed, about %7.1f s left", step.c_str(),
                total ? 100.0 * double(done) / double(total) : 100.0, done, total, elapsed, left);
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

PoseSamples evenlySpacedFrames(const std::vector<AnimationClip>& clips, size_t count) {
  PoseSamples out;
  double total = 0.0;
  for (const AnimationClip& c : clips) total += double(std::max<size_t>(c.frames.size(), 2) - 1);
  for (uint32_t ci = 0; ci < clips.size(); ++ci) {
    const size_t frames = clips[ci].frames.size();
    if (frames == 0) throw Error("clip " + std::to_string(ci) + " '" + clips[ci].name + "' has no frames");
    const double span = double(std::max<size_t>(frames, 2) - 1);  // frames 1 .. frames-1 (or frame 0 alone)
    const size_t k = std::max<size_t>(1, size_t(std::llround(double(count) * span / total)));
    for (size_t i = 0; i < k; ++i) {
      const double f = frames < 2 ? 0.0 : 1.0 + (double(i) + 0.5) * (span - 1.0) / double(k);
      out.origins.push_back({0, ci, float(f), false});
    }
  }
  return out;
}

std::vector<AnimationClip> importClips(const std::vector<ClipSource>& sources, const Skeleton& skeleton,
                                       const std::vector<std::string>& requiredJoints, int threads,
                                       const std::function<void(const std::string&)>& log) {
  // Each clip is read and retargeted on its own (BVH parsing dominates), in parallel; the first
  // failure in list order is reported, naming its file, so the message does not depend on timing.
  const auto start = Clock::now();
  std::vector<AnimationClip> clips(sources.size());
  std::vector<std::string> errors(sources.size());
  auto one = [&](size_t i) {
    const ClipSource& c = sources[i];
    try {
      io::AnimationImportOptions o;
      o.retarget.jointMap.naming = c.naming;
      o.retarget.jointMap.explicitPairs = c.jointMap;
      o.retarget.jointMap.chains = c.jointChains;
      o.retarget.requiredJoints = requiredJoints;
      o.framesPerSecond = c.framesPerSecond;
      clips[i] = io::importAnimation(c.file, skeleton, o);
      if (c.expectedFrames > 0 && clips[i].frames.size() != c.expectedFrames)
        errors[i] = c.file.string() + ": " + std::to_string(clips[i].frames.size()) +
                    " frames, but its index file says " + std::to_string(c.expectedFrames);
    } catch (const Error& e) {
      const std::string what = e.what();
      errors[i] = what.find(c.file.string()) == std::string::npos ? c.file.string() + ": " + what : what;
    }
  };
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(size_t(0), sources.size(), size_t(1), one); });
  } else {
    tbb::parallel_for(size_t(0), sources.size(), size_t(1), one);
  }
  size_t failures = 0;
  for (const auto& e : errors) failures += !e.empty();
  for (const auto& e : errors)
    if (!e.empty())
      throw Error("bake part 1: clip " + e +
                  (failures > 1 ? " (and " + std::to_string(failures - 1) + " more clips failed)" : std::string()));
  if (log) {
    size_t frames = 0;
    std::map<std::string, size_t> perSubject;
    for (size_t i = 0; i < clips.size(); ++i) {
      frames += clips[i].frames.size();
      perSubject[sources[i].subject] += 1;
      if (clips.size() <= 20)
        log("part 1: clip " + sources[i].file.string() + ": " + std::to_string(clips[i].frames.size()) + " frames at " +
            std::to_string(int(clips[i].framesPerSecond)) + " fps" +
            (sources[i].weight != 1.0 ? ", weight " + std::to_string(sources[i].weight) : std::string()));
    }
    std::string subjects;
    for (const auto& [subject, n] : perSubject)
      subjects += (subjects.empty() ? "" : ", ") + (subject.empty() ? std::string("(none)") : subject) + ": " +
                  std::to_string(n);
    char line[160];
    std::snprintf(line, sizeof line,
                  "part 1: %zu clips, %zu frames read and retargeted in %.2f s; clips per subject: ", clips.size(),
                  frames, since(start));
    log(line + subjects);
  }
  return clips;
}

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
    clipList.push_back(
        {{"file", c.file.string()}, {"naming", namingName(c.naming)}, {"joint_map", m}, {"fps", c.framesPerSecond}});
    // Keys that decide the poses only where they are set, so recipes without them keep their datasets.
    if (!c.jointChains.empty()) {
      io::JointMapOptions o;
      o.explicitPairs = c.jointMap;
      o.chains = c.jointChains;
      clipList.back()["joint_map"] = io::jointMapToJson(o);
    }
    if (c.weight != 1.0) clipList.back()["weight"] = c.weight;
  }
  const ClothSimSettings& m = simulation;
  nlohmann::json out = {
      {"character",
       {{"file", characterFile.string()},
        {"recipe", characterRecipe.string()},
        {"body_mesh", bodyMeshNames},
        {"garment_mesh", garmentMeshNames},
        {"simulation_mesh", simulationMeshNames}}},
      {"clips", clipList},
      {"input_joints", inputJoints},
      {"sampling",
       {{"characters", sampling.characters},
        {"seconds_per_character", sampling.secondsPerCharacter},
        {"sample_rate", sampling.sampleRate},
        {"mirror_odd_characters", sampling.mirrorOddCharacters},
        {"speed_jitter", sampling.speedJitter},
        {"seed", sampling.seed}}},
      {"thinning",
       {{"tolerance", thinningTolerance}, {"target_poses", targetPoses}, {"include_rest_pose", includeRestPose}}},
      {"simulation",
       {{"preset", m.material.name},
        {"vertices", simulationVertices},
        {"thickness", m.thickness},
        {"transition_seconds", m.transitionSeconds},
        {"settle_seconds", m.settleSeconds},
        {"frame_rate", m.frameRate},
        {"substeps", m.substeps},
        {"iterations", m.iterations},
        {"equilibrium_tolerance", m.equilibriumTolerance},
        {"equilibrium_seconds", m.equilibriumSeconds},
        {"equilibrium_iterations", m.equilibriumIterations},
        {"retries", m.retries},
        {"final_projection", m.finalProjection},
        {"gravity", -m.gravity.y()},
        {"limb_clearance", limbClearance.clearance},
        {"limb_garment_reach", limbClearance.garmentReach},
        {"limb_neck_range", limbClearance.neckRangeDegrees},
        {"limb_one_surface", limbClearance.oneSurfaceLimbs},
        {"limb_turn_search", limbClearance.turnSearch},
        {"attach_band", m.attachTopFraction}}},
      {"transfer",
       {{"smoothing_strength", transfer.smoothing.strength},
        {"smoothing_iterations", transfer.smoothing.iterations},
        {"smoothing_weights", transfer.smoothing.weights == LaplacianWeights::Cotangent ? "cotangent" : "uniform"},
        {"unskin_min_singular_value", transfer.unskin.minSingularValue},
        {"max_edge_strain", transfer.maxEdgeStrain}}},
      {"normal_maps",
       {{"size", transfer.normalMap.width},
        {"max_distance", transfer.normalMap.maxDistance},
        {"dilation_rings", transfer.normalMap.dilationRings},
        {"bit_depth", normalMapBitDepth}}},
  };
  // Set only where used, so that recipes without them keep their datasets.
  if (!holdoutSubjects.empty()) out["holdout"] = {{"subjects", holdoutSubjects}, {"poses", holdoutPoses}};
  if (evenPoses > 0) out["even_poses"] = evenPoses;
  if (growFrom > 0 && evenPoses == 0) out["thinning"]["grow_from"] = growFrom;
  if (synthesis.enabled() && evenPoses == 0)
    out["synthesis"] = {{"joints", synthesis.joints},
                        {"poses", synthesis.poses},
                        {"candidates", synthesis.candidates},
                        {"extend", synthesis.extend},
                        {"seed", synthesis.seed}};
  // Only when overridden, so that the settings (and so the datasets) of other bakes stay as they were.
  const auto& presets = clothMaterialPresets();
  const auto preset =
      std::find_if(presets.begin(), presets.end(), [&](const ClothMaterial& c) { return c.name == m.material.name; });
  if (preset == presets.end() || m.material.friction != preset->friction)
    out["simulation"]["friction"] = m.material.friction;
  if (preset == presets.end() || m.material.damping != preset->damping)
    out["simulation"]["damping"] = m.material.damping;
  // Only when external, so that the settings (and so the datasets) of solver bakes stay as they were.
  if (external.enabled()) out["simulation"].update(external.toJson());
  // Only when on, likewise.
  if (m.equilibriumSubsteps > 0) out["simulation"]["equilibrium_substeps"] = m.equilibriumSubsteps;
  if (m.staticSolve) {
    out["simulation"]["static_solve"] = true;
    out["simulation"]["static_tolerance"] = m.staticTolerance;
    out["simulation"]["static_iterations"] = m.staticIterations;
  }
  if (m.carry != ClothCarry::Skinning) out["simulation"]["carry"] = clothCarryName(m.carry);  // likewise
  if (m.saferPathRetries) out["simulation"]["safer_path_retries"] = true;                     // likewise
  if (transfer.reskinMinSingularValue > 0.f)                                                  // likewise
    out["transfer"]["reskin_min_singular_value"] = transfer.reskinMinSingularValue;
  if (transfer.cover.enabled()) {  // likewise
    out["transfer"]["cover_body_mm"] = 1000.f * transfer.cover.margin;
    out["transfer"]["cover_recorded_pose"] = transfer.cover.recordedPose;
  }
  if (!m.skinningRetriesOnly()) {  // likewise
    nlohmann::json& list = out["simulation"]["retry_carries"] = nlohmann::json::array();
    for (ClothCarry c : m.retryCarries) list.push_back(clothCarryName(c));
  }
  return out;
}

nlohmann::json DatasetBuildResult::toJson() const {
  nlohmann::json f = nlohmann::json::array();
  for (const FailedPose& p : failed) f.push_back({{"pose", p.id}, {"reason", p.reason}});
  nlohmann::json st = nlohmann::json::array();
  for (const DatasetBuildStep& s : steps) st.push_back({{"step", s.name}, {"seconds", s.seconds}});
  return {{"clip_frames", clipFrames},
          {"samples", samples},
          {"kept_poses", keptPoses},
          {"rest_pose_added", restPoseAdded},
          {"synthesized_poses", synthesizedPoses},
          {"synthesis_candidates", synthesisCandidates},
          {"tolerance", tolerance},
          {"poses_corrected", posesCorrected},
          {"max_correction_degrees", maxCorrectionDegrees},
          {"neck_range_poses", neckRangePoses},
          {"corrections_by_joint",
           [&] {
             nlohmann::json j = nlohmann::json::object();
             for (const auto& [joint, c] : correctionsByJoint)
               j[joint] = {{"poses", c.poses}, {"mean_degrees", c.meanDegrees}, {"max_degrees", c.maxDegrees}};
             return j;
           }()},
          {"max_correction_towards_rest", maxTowardsRest},
          {"simulation_vertices", simulationVertices},
          {"simulated", simulated},
          {"simulations_reused", simulationsReused},
          {"transferred", transferred},
          {"transfers_reused", transfersReused},
          {"unskin_damped",
           {{"poses", unskinDampedPoses},
            {"max_vertices", unskinDampedMaxVertices},
            {"smallest_singular_value", unskinSmallestSingularValue}}},
          {"body_cover", bodyCover.toJson()},
          {"body_cover_recorded_pose", bodyCoverRecorded.toJson()},
          {"failed", f},
          {"rebuilt", rebuilt},
          {"simulation", simulationReport},
          {"steps", st}};
}

void DatasetBuildResult::BodyCoverSummary::add(const BodyCoverStats& s) {
  if (s.verticesMoved == 0 && s.samplesLeft == 0) return;
  poses += s.verticesMoved > 0;
  vertices += s.verticesMoved;
  posesLeftThrough += s.samplesLeft > 0;
  posesHeld += s.verticesHeld > 0;
  verticesHeld += s.verticesHeld;
  largestShift = std::max(largestShift, s.largestShift);
  deepest = std::max(deepest, s.deepest);
}

nlohmann::json DatasetBuildResult::BodyCoverSummary::toJson() const {
  return {{"poses", poses},
          {"vertices_moved", vertices},
          {"largest_shift_mm", 1000.0 * largestShift},
          {"deepest_before_mm", 1000.0 * deepest},
          {"poses_left_through", posesLeftThrough},
          {"poses_held_back", posesHeld},
          {"vertices_held_back", verticesHeld}};
}

std::vector<uint64_t> DatasetPosePlan::poseFingerprints() const {
  std::vector<uint64_t> f(toSimulate.size());
  for (size_t i = 0; i < f.size(); ++i) f[i] = poseFingerprint(shapes->solver(), toSimulate[i]);
  return f;
}

uint64_t DatasetPosePlan::fingerprint() const {
  Fnv1a f;
  const std::string settings = settingsJson.dump();
  f.bytes(settings.data(), settings.size());
  f.vec(poseFingerprints());
  return f.h;
}

DatasetPosePlan planDatasetPoses(const DatasetBuildSettings& s, const std::function<void(const std::string&)>& logFn,
                                 const std::function<std::vector<uint32_t>(size_t)>& clearOnly) {
  auto log = [&](const std::string& line) {
    if (logFn) logFn(line);
  };
  DatasetPosePlan plan;
  DatasetBuildResult& res = plan.result;
  auto step = [&](const std::string& name, Clock::time_point t) { res.steps.push_back({name, since(t)}); };
  if (s.clips.empty()) throw Error("bake part 1: no animation clips");
  if (s.evenPoses == 0 && (s.thinningTolerance > 0.f) == (s.targetPoses > 0))
    throw Error("bake part 1: give exactly one of a thinning tolerance and a target pose count");
  s.simulation.validate();

  // Character and clips.
  auto t = Clock::now();
  plan.character = std::make_unique<const Character>(loadDatasetCharacter(s));
  const Character& character = *plan.character;
  std::vector<uint32_t>& inputJoints = plan.inputJoints;
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

  t = Clock::now();
  const std::vector<AnimationClip> clips = importClips(s.clips, character.skeleton, s.inputJoints, s.threads, log);
  for (const AnimationClip& c : clips) res.clipFrames += c.frames.size();
  step("clips", t);

  // Poses: sample, thin, back to full-skeleton poses.
  t = Clock::now();
  PoseSamplingOptions so = s.sampling;
  so.joints = s.inputJoints;
  if (std::any_of(s.clips.begin(), s.clips.end(), [](const ClipSource& c) { return c.weight != 1.0; }))
    for (const ClipSource& c : s.clips) so.clipWeights.push_back(c.weight);
  const PoseSamples samples =
      s.evenPoses > 0 ? evenlySpacedFrames(clips, s.evenPoses) : samplePoses(character.skeleton, clips, so);
  res.samples = samples.origins.size();
  ThinningResult thin;
  if (s.evenPoses > 0) {
    for (uint32_t k = 0; k < samples.origins.size(); ++k) thin.kept.push_back(k);
  } else {
    thin = s.targetPoses > 0 ? thinPosesToCount(samples, s.growFrom > 0 ? s.growFrom : s.targetPoses)
                             : thinPoses(samples, s.thinningTolerance);
  }
  std::vector<Pose>& poses = plan.toSimulate;
  res.origins = nlohmann::json::array();
  auto originJson = [&](const PoseSamples::Origin& o) {  // pose_origins.json's entry for a sample
    return nlohmann::json{{"clip", s.clips[o.clip].file.stem().string()},
                          {"subject", s.clips[o.clip].subject},
                          {"frame", o.frame},
                          {"mirrored", o.mirrored}};
  };
  auto addKept = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; ++i) {
      const PoseSamples::Origin& o = samples.origins[thin.kept[i]];
      poses.push_back(canonicalPose(character.skeleton, poseOfSample(character.skeleton, clips, o)));
      res.origins.push_back(originJson(o));
    }
  };
  addKept(0, thin.kept.size());
  {
    char line[200];
    std::snprintf(line, sizeof line, "part 1: %zu samples thinned to %zu poses (tolerance %.4f, %d passes) in %.2f s",
                  res.samples, poses.size(), double(thin.tolerance), thin.passes, since(t));
    log(line);
  }
  int64_t restPoseId = -1;
  if (s.includeRestPose && s.evenPoses == 0) {
    const Pose rest = canonicalPose(character.skeleton, character.skeleton.restPose());
    const float nearest = nearestKeptDistance(samples, thin.kept, runtime::computeTheta(inputJoints, rest.local));
    if (nearest > thin.tolerance) {
      restPoseId = int64_t(poses.size());
      poses.push_back(rest);
      res.restPoseAdded = true;
      res.origins.push_back({{"clip", "rest pose"}});
    }
    char line[200];
    std::snprintf(line, sizeof line, "part 1: the rest pose is %.4f from the nearest kept pose: ", double(nearest));
    log(line + (res.restPoseAdded ? "added as pose " + std::to_string(restPoseId) : std::string("already covered")));
  }
  // Growing a smaller bake's pose list: its poses (and its rest pose) keep their ids, so their
  // simulations are reused; a second greedy pass at a smaller tolerance adds the rest after them.
  if (s.growFrom > 0 && s.evenPoses == 0) {
    const auto t2 = Clock::now();
    const size_t first = thin.kept.size();
    const float firstTolerance = thin.tolerance;
    ThinToCountOptions grow;
    grow.keepFirst = thin.kept;
    thin = thinPosesToCount(samples, s.targetPoses, grow);
    addKept(first, thin.kept.size());
    char line[240];
    std::snprintf(line, sizeof line,
                  "part 1: grown from the %zu poses of tolerance %.4f (ids 0..%zu kept) to %zu (tolerance %.4f, %d "
                  "passes) in %.2f s",
                  first, double(firstTolerance), first - (res.restPoseAdded ? 0 : 1), poses.size(),
                  double(thin.tolerance), thin.passes, since(t2));
    log(line);
  }
  res.tolerance = thin.tolerance;
  // Synthesized poses (pose_synthesis.hpp), after every recorded pose so that those keep their ids.
  if (s.synthesis.enabled() && s.evenPoses == 0) {
    const auto t2 = Clock::now();
    const SynthesisResult syn =
        synthesizePoses(character.skeleton, clips, samples, thin.kept, inputJoints, s.synthesis);
    for (const SynthesizedPose& sp : syn.added) {
      poses.push_back(canonicalPose(character.skeleton, poseOfSynthesized(character.skeleton, clips, sp)));
      nlohmann::json o = originJson(sp.base), draws = nlohmann::json::array();
      for (const SynthesizedPose::Draw& d : sp.draws) {
        nlohmann::json dj = originJson(d.donor);
        dj["joint"] = character.skeleton.joints[d.joint].name;
        dj["t"] = d.t;
        draws.push_back(dj);
      }
      o["synthesized"] = draws;
      res.origins.push_back(o);
    }
    res.synthesizedPoses = syn.added.size();
    res.synthesisCandidates = syn.candidates;
    char line[240];
    std::snprintf(line, sizeof line,
                  "part 1: synthesis: %zu poses of %zu candidates (%zu joints redrawn) added after the recorded ones "
                  "(tolerance %.4f, %d passes) in %.2f s",
                  syn.added.size(), syn.candidates, s.synthesis.joints.size(), double(syn.tolerance), syn.passes,
                  since(t2));
    log(line);
  }
  res.keptPoses = poses.size();
  step("sampling + thinning", t);

  // Clearance, simulation and transfer of one pose are PoseShapeSimulator's steps (pose_shape.hpp),
  // shared with `swish replay --truth-every`; here each step runs over all poses in turn.
  t = Clock::now();
  plan.shapes = std::make_unique<const PoseShapeSimulator>(character, s.poseShape());
  const PoseShapeSimulator& shapes = *plan.shapes;
  step("simulation setup", t);

  // Limbs out of the trunk: the corrected poses are simulated; the dataset keeps the recorded poses,
  // which are what the model sees at run time (see the transfer below).
  plan.recorded = poses;
  const std::vector<Pose>& recorded = plan.recorded;
  if (shapes.clearance()) {
    t = Clock::now();
    const LimbClearance& clearance = *shapes.clearance();
    std::vector<std::vector<LimbCorrection>> corrections(poses.size());
    std::vector<uint32_t> cleared;
    if (clearOnly) {
      cleared = clearOnly(poses.size());
      for (const uint32_t i : cleared)
        if (i >= poses.size())
          throw Error("bake part 1: pose " + std::to_string(i) + " to clear of " + std::to_string(poses.size()));
    } else {
      cleared.resize(poses.size());
      for (uint32_t i = 0; i < cleared.size(); ++i) cleared[i] = i;
    }
    tbb::parallel_for(size_t(0), cleared.size(), [&](size_t k) {
      const uint32_t i = cleared[k];
      poses[i] = shapes.poseToSimulate(recorded[i], &corrections[i]);
    });
    size_t stillInside = 0, neckPoses = 0;
    double neckMean = 0.0, neckMax = 0.0;
    for (const auto& c : corrections) {
      if (std::any_of(c.begin(), c.end(), [](const LimbCorrection& x) { return !x.neckRange; })) ++res.posesCorrected;
      for (const LimbCorrection& x : c) {
        if (x.neckRange) {  // reported on its own line below
          ++neckPoses;
          neckMean += double(x.degrees);
          neckMax = std::max(neckMax, double(x.degrees));
          continue;
        }
        res.maxCorrectionDegrees = std::max(res.maxCorrectionDegrees, x.degrees);
        if (x.depthAfter > 0.f) ++stillInside;
        DatasetBuildResult::JointCorrections& j = res.correctionsByJoint[x.joint];
        ++j.poses;
        j.meanDegrees += double(x.degrees);  // a sum until divided below
        j.maxDegrees = std::max(j.maxDegrees, double(x.degrees));
      }
    }
    std::string byJoint;
    for (auto& [joint, j] : res.correctionsByJoint) {
      j.meanDegrees /= double(std::max<size_t>(1, j.poses));
      char one[160];
      std::snprintf(one, sizeof one, "%s%s %zu poses (mean %.0f, max %.0f degrees)", byJoint.empty() ? "" : ", ",
                    joint.c_str(), j.poses, j.meanDegrees, j.maxDegrees);
      byJoint += one;
    }
    if (!clearance.skipped().empty()) log("part 1: limb clearance skipped: " + clearance.skipped());
    char line[320];
    if (clearance.limbCount() > 0)
      std::snprintf(
          line, sizeof line,
          "part 1: limb clearance %.0f mm: %zu of %zu poses had a limb in the trunk where the garment is (%zu "
          "limbs of the body checked%s, %zu of the trunk's %zu triangles within %.0f mm of the garment); "
          "turned out by up to %.0f degrees, %zu limbs still inside, in %.2f s",
          1000.0 * s.limbClearance.clearance, res.posesCorrected, cleared.size(), clearance.limbCount(),
          clearance.limbsAreRegions() ? ": skin regions of a body that is one surface" : "",
          clearance.guardedTriangles(), clearance.trunkTriangles(), 1000.0 * s.limbClearance.garmentReach,
          double(res.maxCorrectionDegrees), stillInside, since(t));
    if (clearance.limbCount() > 0) log(line);
    if (!byJoint.empty()) log("part 1: turned out, by joint: " + byJoint);
    res.neckRangePoses = neckPoses;
    if (neckPoses > 0) {
      char neck[200];
      std::snprintf(neck, sizeof neck,
                    "part 1: neck range %.0f degrees: %zu poses turned the neck chain further, turned back to it "
                    "(mean %.0f, max %.0f degrees taken off)",
                    double(s.limbClearance.neckRangeDegrees), neckPoses, neckMean / double(neckPoses), neckMax);
      log(neck);
    }
    if (clearance.checksHead()) {
      size_t headPoses = 0, headInside = 0;
      float headDegrees = 0.f;
      for (const auto& c : corrections) {
        headPoses += std::any_of(c.begin(), c.end(), [](const LimbCorrection& x) { return x.head; });
        for (const LimbCorrection& x : c)
          if (x.head) {
            res.maxTowardsRest = std::max(res.maxTowardsRest, x.towardsRest);
            headDegrees = std::max(headDegrees, x.degrees);
            headInside += x.depthAfter > 0.f;
          }
      }
      std::snprintf(line, sizeof line,
                    "part 1: head clearance (one-surface body, %zu head vertices checked): %zu of %zu poses had the "
                    "head inside the body; neck turned back towards rest by up to %.0f %% (%.0f degrees), %zu still "
                    "inside, in %.2f s",
                    clearance.headVertexCount(), headPoses, cleared.size(), 100.0 * res.maxTowardsRest,
                    double(headDegrees), headInside, since(t));
      log(line);
      for (size_t i = 0; i < corrections.size(); ++i)
        for (const LimbCorrection& x : corrections[i]) {
          if (!x.head) continue;  // the neck range and the limbs have their own lines
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

  // What the dataset folder records of the settings and the pose list.
  nlohmann::json& settingsJson = plan.settingsJson;
  settingsJson = s.toJson();
  settingsJson["pose_list_digest"] = std::to_string(poseListDigest(poses));
  settingsJson["kept_poses"] = poses.size();
  settingsJson["thinning_tolerance_used"] = thin.tolerance;
  // Part 2 keeps this pose in its training split (part2_training.cpp); -1: none was added.
  settingsJson["rest_pose_id"] = restPoseId;
  // Part 2 never holds these out: its random held-out poses are recorded frames (part2_training.cpp).
  if (res.synthesizedPoses > 0) settingsJson["synthesized_from_id"] = poses.size() - res.synthesizedPoses;
  return plan;
}

DatasetPoseList listDatasetPoses(const DatasetBuildSettings& s, DatasetBuildResult& res,
                                 const std::function<void(const std::string&)>& logFn) {
  DatasetPosePlan plan = planDatasetPoses(s, logFn);
  DatasetPoseList out;
  out.character = std::move(plan.character);
  out.inputJoints = std::move(plan.inputJoints);
  out.recorded = std::move(plan.recorded);
  out.simulated = std::move(plan.toSimulate);
  out.shapes = std::move(plan.shapes);
  out.thinningTolerance = plan.result.tolerance;
  out.digest = poseListDigest(out.simulated);
  res = std::move(plan.result);
  return out;
}

DatasetBuildResult buildDataset(const DatasetBuildSettings& s, const fs::path& datasetDir,
                                const fs::path& simulationDir, const fs::path& previewDir,
                                const std::function<void(const std::string&)>& logFn) {
  auto log = [&](const std::string& line) {
    if (logFn) logFn(line);
  };
  DatasetPosePlan plan = planDatasetPoses(s, logFn);
  if (s.simulatedPoseList != 0 && plan.fingerprint() != s.simulatedPoseList) {
    char line[320];
    std::snprintf(line, sizeof line,
                  "bake part 1: this recipe now thins to the pose list %016llx, not the %016llx the cluster's array "
                  "tasks simulated: the recipe, its clips or swish changed after `swish bake --slurm`; submit again",
                  static_cast<unsigned long long>(plan.fingerprint()),
                  static_cast<unsigned long long>(s.simulatedPoseList));
    throw Error(line);
  }
  DatasetBuildResult res = std::move(plan.result);
  auto step = [&](const std::string& name, Clock::time_point t) { res.steps.push_back({name, since(t)}); };
  const Character& character = *plan.character;
  const PoseShapeSimulator& shapes = *plan.shapes;
  const std::vector<Pose>& poses = plan.toSimulate;
  const std::vector<Pose>& recorded = plan.recorded;
  nlohmann::json settingsJson = plan.settingsJson;
  auto t = Clock::now();

  // External shapes: read (and checked against the pose list) before the dataset is touched.
  std::unique_ptr<ExternalShapeSource> external;
  if (s.external.enabled()) {
    const TransitionClipSettings clip = clipSettingsOf(s.simulation);
    std::vector<TransitionMarker> markers;
    buildTransitionFrames(character.skeleton, poses, clip, markers);
    std::vector<uint32_t> targetFrames;
    for (const TransitionMarker& m : markers) targetFrames.push_back(m.targetFrame);
    external =
        std::make_unique<ExternalShapeSource>(s.external, shapes.solver().mesh().restPositions,
                                              shapes.solver().mesh().triangles, targetFrames, poseListDigest(poses));
    log("part 1: " + external->description());
    if (external->maxBindingDistance() > 0.f) {
      char line[160];
      std::snprintf(line, sizeof line,
                    "part 1: re-meshed garment bound to the simulation mesh: farthest vertex %.2f mm "
                    "from the re-meshed rest surface",
                    1000.0 * external->maxBindingDistance());
      log(line);
    }
    // A changed result file of an external tool changes the shapes: rebuild the dataset's poses.
    settingsJson["external_files_digest"] = std::to_string(external->digest());
    step("external simulation setup", t);
  }

  // Dataset folder: reset when its poses were made with other settings or another pose list.
  res.rebuilt = resetDatasetIfStale(datasetDir, settingsJson, logFn);
  const DatasetWriter writer(datasetDir, character, plan.inputJoints, settingsJson, s.normalMapBitDepth);
  writeTextFileAtomic(datasetDir / "pose_origins.json", res.origins.dump(1) + "\n");

  // Simulation (resumable per pose; failures are recorded in their files and left out), unless the
  // shapes come from an external tool's files.
  t = Clock::now();
  const ClothSolver& solver = shapes.solver();
  res.simulationVertices = solver.mesh().vertexCount();
  PoseSimulationRun sim;
  log("part 1: simulation mesh " + std::to_string(res.simulationVertices) + " vertices, " +
      std::to_string(solver.mesh().triangles.rows()) + " triangles" +
      (external ? std::string(", shapes from the external simulation")
                : ", preset '" + s.simulation.material.name + "'"));
  if (s.simulatedPoseList != 0 && !external) {
    // Made by a cluster's array tasks: every pose must be there; none is simulated here.
    std::vector<uint32_t> missing;
    for (uint32_t id = 0; id < poses.size(); ++id)
      if (!loadFinishedPose(simulationDir, id, solver, poses[id])) missing.push_back(id);
    if (!missing.empty()) {
      std::string ids;
      for (size_t k = 0; k < missing.size() && k < 10; ++k) ids += (k ? ", " : "") + std::to_string(missing[k]);
      throw Error("bake part 1: " + std::to_string(missing.size()) + " of " + std::to_string(poses.size()) +
                  " poses have no finished simulation in " + simulationDir.string() + " (pose " + ids +
                  (missing.size() > 10 ? ", ..." : "") + "); the array tasks that own them did not finish");
    }
  }
  if (!external) {
    ProgressThrottle simThrottle;
    const auto simStart = Clock::now();
    sim = simulatePoses(
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
  }

  // Transfer + smoothing + normal map per pose, in parallel, each pose written when done.
  t = Clock::now();
  std::mutex mutex;
  std::vector<uint32_t> todo;
  for (uint32_t id = 0; id < poses.size(); ++id) {
    const bool failed =
        std::any_of(sim.failures.begin(), sim.failures.end(), [&](const auto& f) { return f.first == id; });
    if (failed) continue;
    if (writer.hasPose(id))
      ++res.transfersReused;
    else
      todo.push_back(id);
  }
  std::atomic<size_t> done{0};
  ProgressThrottle transferThrottle;
  const auto transferStart = Clock::now();
  const size_t total = todo.size();
  auto counted = [&](const TransferredPose& tp) {
    std::lock_guard<std::mutex> lock(mutex);
    res.bodyCover.add(tp.cover);
    res.bodyCoverRecorded.add(tp.coverRecorded);
  };
  auto one = [&](size_t k) {
    const uint32_t id = todo[k];
    std::string failure;
    try {
      if (external) {
        // Another tool's shape: read, matched to the simulation mesh, then the same transfer.
        Points3f positions;
        try {
          positions = external->shape(id);
        } catch (const Error& e) {
          failure = std::string("external simulation: ") + e.what();
        }
        if (failure.empty()) {
          TransferredPose tp = shapes.gameMeshShape(poses[id], recorded[id], positions);
          counted(tp);
          DatasetPose dp;
          dp.id = id;
          dp.pose = recorded[id];
          dp.gameMeshWorld = std::move(tp.gameMeshWorld);
          dp.gameMeshPreSkin = std::move(tp.gameMeshPreSkin);
          dp.normalMap = std::move(tp.normalMap);
          dp.residuals = solver.measure(poses[id], positions);
          if (dp.residuals.maxPenetration > s.simulation.failPenetration) {
            char line[200];
            std::snprintf(line, sizeof line,
                          "part 1: pose %u (external): the garment ends %.1f mm inside the body "
                          "(the solver's bound is %.1f mm); kept, as the external tool made it",
                          id, 1000.0 * dp.residuals.maxPenetration, 1000.0 * s.simulation.failPenetration);
            std::lock_guard<std::mutex> lock(mutex);
            log(line);
          }
          writer.writePose(dp);
        }
      } else if (const auto rec = loadFinishedPose(simulationDir, id, solver, poses[id]); !rec || !rec->result.ok) {
        failure = "simulation result missing or not usable";
      } else {
        // The pre-skin shape from the corrected simulation, the world shape skinned with the
        // recorded pose (pose_shape.hpp); the dataset keeps the recorded pose.
        TransferredPose tp = shapes.gameMeshShape(poses[id], recorded[id], rec->result.positions);
        counted(tp);
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
  // Poses whose garment skinning collapses (damped un-skinning, core/skinning.hpp), over every pose in
  // the dataset: a property of the simulated pose, so reused transfers count too.
  {
    size_t inDataset = 0;
    for (uint32_t id = 0; id < poses.size(); ++id) {
      if (std::any_of(res.failed.begin(), res.failed.end(), [&](const FailedPose& f) { return f.id == id; })) continue;
      ++inDataset;
      const UnskinStats u =
          collapsedSkinning(character.garment.skin, character.skeleton.skinningMatrices(poses[id]), s.transfer.unskin);
      if (u.dampedVertices == 0) continue;
      ++res.unskinDampedPoses;
      res.unskinDampedMaxVertices = std::max(res.unskinDampedMaxVertices, u.dampedVertices);
      res.unskinSmallestSingularValue = std::min(res.unskinSmallestSingularValue, u.smallestSingularValue);
    }
    if (res.unskinDampedPoses > 0) {
      char line[300];
      std::snprintf(line, sizeof line,
                    "part 1: %zu of %zu poses have garment vertices where skinning collapses (up to %zu in a "
                    "pose, smallest singular value %.3f): un-skinned damped towards rest (core/skinning.hpp)",
                    res.unskinDampedPoses, inDataset, res.unskinDampedMaxVertices,
                    double(res.unskinSmallestSingularValue));
      log(line);
    }
  }
  // What the cover did (transfer/body_cover.hpp): in the simulated pose, then again in the recorded one.
  for (const auto& [c, what] :
       {std::pair{&res.bodyCover, "the game mesh kept over the body (cover_body_mm)"},
        std::pair{&res.bodyCoverRecorded, "and again in the recorded pose, where limb clearance had turned a limb,"}}) {
    if (c->poses == 0) continue;
    char line[420];
    std::snprintf(line, sizeof line,
                  "part 1: %s in %zu of %zu poses transferred: %.0f vertices moved per such pose, at most %.1f mm; the "
                  "body was up to %.1f mm through; %zu poses still have some of it through; %zu held back moves "
                  "so as not to tear an edge",
                  what, c->poses, res.transferred, double(c->vertices) / double(c->poses), 1000.0 * c->largestShift,
                  1000.0 * c->deepest, c->posesLeftThrough, c->posesHeld);
    log(line);
  }
  nlohmann::json source = {{"tool", "swish bake (part 1)"},
                           {"samples", res.samples},
                           {"kept_poses", res.keptPoses},
                           {"simulation_vertices", res.simulationVertices}};
  if (external) source["simulation"] = external->description();
  writer.writeManifest(res.failed, source);
  step("transfer + normal maps", t);

  // The simulation's own figures: failures per reason, retries, residuals, seconds per pose per core;
  // convergence and noise on a seeded sample of the kept poses (cached beside the simulations). An
  // external tool's shapes have no solver figures: its report says which files it read instead.
  if (!external) {
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
          const auto rec = loadFinishedPose(simulationDir, id, solver, poses[id]);
          shapes.push_back(rec ? rec->result.positions : Points3f());
        }
        SimulationQualitySettings qs = s.quality;
        qs.threads = s.threads;
        log("part 1: measuring the simulation's convergence and noise on " + std::to_string(ids.size()) + " poses");
        ProgressThrottle qThrottle;
        const SimulationQuality q =
            measureSimulationQuality(character, solver, poses, ids, shapes, qs, [&](const std::string& line) {
              if (qThrottle.due(0, 1)) log("part 1: " + line);
            });
        quality = q.toJson();
        writeTextFileAtomic(cache,
                            nlohmann::json{{"fingerprint", std::to_string(fp)}, {"quality", quality}}.dump(2) + "\n");
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
      log("part 1: simulation " + simulationQualityDetail(quality));
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
  if (s.external.enabled())
    throw Error("simulation check: part1.simulation.source is \"external\": there is no solver to check");
  // The sample depends on the pose count only: limb clearance runs on the sampled poses alone.
  auto sample = [&](size_t count) {
    std::vector<uint32_t> every(count);
    for (uint32_t i = 0; i < every.size(); ++i) every[i] = i;
    return sampleQualityPoses(every, poseCount, seed);
  };
  const DatasetPosePlan plan = planDatasetPoses(s, log, sample);
  const Character& character = *plan.character;
  const std::vector<Pose>& poses = plan.toSimulate;  // the sample's limbs out of the trunk, as the bake simulates
  const std::vector<uint32_t> ids = sample(poses.size());
  const ClothSolver& solver = plan.shapes->solver();
  log("simulation check: " + std::to_string(ids.size()) + " of the " + std::to_string(poses.size()) +
      " thinned poses (seed " + std::to_string(seed) + "), " + std::to_string(solver.mesh().vertexCount()) +
      " simulation vertices, preset '" + s.simulation.material.name + "'");

  // One solve per sampled pose.
  std::vector<PoseSimulation> results(ids.size());
  std::mutex mutex;
  size_t done = 0;
  ProgressThrottle throttle;
  const auto simStart = Clock::now();
  auto one = [&](size_t k) {
    const uint32_t id = ids[k];
    results[k] = solver.simulate(poses[id]);
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (!results[k].ok)
      log("simulation check: pose " + std::to_string(id) + " failed: " + results[k].failure);
    else if (results[k].attempts > 1)
      log("simulation check: pose " + std::to_string(id) +
          " kept after a retry; first attempt: " + results[k].firstFailure);
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
                        {"thinned_poses", poses.size()},
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
    log("simulation check: convergence, noise and path sensitivity on " + std::to_string(q.size()) +
        " poses (4 solves each)");
    ProgressThrottle qThrottle;
    out["simulation"]["quality"] =
        measureSimulationQuality(character, solver, poses, q, qShapes, qs, [&](const std::string& l) {
          if (qThrottle.due(0, 1)) log(l);
        }).toJson();
  }
  out["seconds"] = since(start);
  return out;
}

}  // namespace swish::bake
