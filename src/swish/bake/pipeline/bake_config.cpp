#include "swish/bake/pipeline/bake_config.hpp"

#include <cctype>
#include <set>
#include <sstream>

#include "swish/bake/poses/clip_list.hpp"
#include "swish/core/error.hpp"
#include "swish/files/json_file.hpp"

namespace swish::bake {

namespace {
struct Checker {
  std::string source;
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw Error((source.empty() ? "" : source + ": ") + key + ": " + problem);
  }
  void onlyKeys(const nlohmann::json& obj, const std::string& prefix, const std::set<std::string>& allowed) const {
    if (!obj.is_object()) fail(prefix.empty() ? "(top level)" : prefix, "must be a JSON object");
    for (auto it = obj.begin(); it != obj.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(prefix + (prefix.empty() ? "" : ".") + it.key(), "unknown key (known: " + list + ")");
      }
  }
  double number(const nlohmann::json& obj, const std::string& prefix, const std::string& key, double lo, double hi,
                double fallback, bool integer = false) const {
    if (!obj.contains(key)) return fallback;
    const auto& v = obj.at(key);
    const std::string name = prefix + "." + key;
    if (!v.is_number()) fail(name, "must be a number");
    const double d = v.get<double>();
    if (integer && (!v.is_number_integer() && d != double(int64_t(d)))) fail(name, "must be an integer");
    if (!(d >= lo && d <= hi)) {
      std::ostringstream s;
      s << d << " is outside " << lo << ".." << hi;
      fail(name, s.str());
    }
    return d;
  }
  std::string string(const nlohmann::json& obj, const std::string& key, const std::string& fallback,
                     const std::string& prefix = "") const {
    if (!obj.contains(key)) return fallback;
    if (!obj.at(key).is_string() || obj.at(key).get<std::string>().empty())
      fail(prefix + (prefix.empty() ? "" : ".") + key, "must be a non-empty string");
    return obj.at(key).get<std::string>();
  }
  bool boolean(const nlohmann::json& obj, const std::string& prefix, const std::string& key, bool fallback) const {
    if (!obj.contains(key)) return fallback;
    if (!obj.at(key).is_boolean()) fail(prefix + "." + key, "must be true or false");
    return obj.at(key).get<bool>();
  }
  std::vector<std::string> strings(const nlohmann::json& obj, const std::string& prefix, const std::string& key,
                                   std::vector<std::string> fallback) const {
    if (!obj.contains(key)) return fallback;
    const auto& v = obj.at(key);
    if (!v.is_array() || v.empty()) fail(prefix + "." + key, "must be a non-empty array of strings");
    std::vector<std::string> out;
    for (const auto& e : v) {
      if (!e.is_string() || e.get<std::string>().empty()) fail(prefix + "." + key, "must hold non-empty strings only");
      out.push_back(e.get<std::string>());
    }
    return out;
  }
  // A file the bake reads: resolved against the config's folder, and it must exist now (before any work).
  std::filesystem::path existingFile(const nlohmann::json& obj, const std::string& name,
                                     const std::filesystem::path& baseDir) const {
    if (!obj.is_string() || obj.get<std::string>().empty()) fail(name, "must be a non-empty string (a file path)");
    const std::filesystem::path f = baseDir / obj.get<std::string>();
    if (!std::filesystem::is_regular_file(f)) fail(name, "file " + f.string() + " does not exist");
    return f;
  }
};

void parseCharacter(const Checker& c, const nlohmann::json& v, const std::filesystem::path& baseDir,
                    DatasetBuildSettings& s) {
  const std::string p = "part1.character";
  if (v.is_string()) {
    if (v.get<std::string>() != "default") c.fail(p, "must be \"default\" or an object with \"file\" or \"recipe\"");
    return;
  }
  c.onlyKeys(v, p, {"file", "recipe", "body_mesh", "garment_mesh", "simulation_mesh"});
  if (v.contains("file") == v.contains("recipe")) c.fail(p, "give exactly one of \"file\" and \"recipe\"");
  if (v.contains("recipe")) {
    s.characterRecipe = c.existingFile(v.at("recipe"), p + ".recipe", baseDir);
    if (v.size() > 1) c.fail(p, "mesh names apply to an imported \"file\" only");
    return;
  }
  s.characterFile = c.existingFile(v.at("file"), p + ".file", baseDir);
  s.bodyMeshNames = c.strings(v, p, "body_mesh", {});
  s.garmentMeshNames = c.strings(v, p, "garment_mesh", {});
  s.simulationMeshNames = c.strings(v, p, "simulation_mesh", {});
}

// part1.simulation "source": "solver" (the default) or "external" with "path" and the space keys
// (external_simulation.hpp). The path is resolved by parsePart1 (a dataset's or model's settings
// carry it as it was resolved then).
void parseSimulationSource(const Checker& c, const nlohmann::json& sim, const std::string& p, DatasetBuildSettings& s) {
  const std::string source = c.string(sim, "source", "solver", p);
  if (source != "solver" && source != "external")
    c.fail(p + ".source", "'" + source + "' is not one of solver, external");
  const bool external = source == "external";
  for (const char* k : {"path", "space", "units_per_metre", "up_axis", "origin"})
    if (!external && sim.contains(k)) c.fail(p + "." + k, "applies to \"source\": \"external\" only");
  if (!external) return;
  if (!sim.contains("path"))
    c.fail(p + ".path",
           "is required with \"source\": \"external\" (the folder of pose_<id>.obj files, or one "
           "multi-frame .glb/.gltf/.fbx)");
  ExternalSimulationSettings& e = s.external;
  e.path = c.string(sim, "path", "", p);
  const std::string space = c.string(sim, "space", "character", p);
  if (space != "character" && space != "world") c.fail(p + ".space", "'" + space + "' is not one of character, world");
  e.worldSpace = space == "world";
  for (const char* k : {"units_per_metre", "up_axis", "origin"})
    if (!e.worldSpace && sim.contains(k)) c.fail(p + "." + k, "applies to \"space\": \"world\" only");
  e.unitsPerMetre = c.number(sim, p, "units_per_metre", 1e-6, 1e6, 1.0);
  const std::string up = c.string(sim, "up_axis", "y", p);
  if (up != "y" && up != "z") c.fail(p + ".up_axis", "'" + up + "' is not one of y, z");
  e.upAxis = up[0];
  if (sim.contains("origin")) {
    const auto& o = sim.at("origin");
    if (!o.is_array() || o.size() != 3 || !o[0].is_number() || !o[1].is_number() || !o[2].is_number())
      c.fail(p + ".origin", "must be [x, y, z] (the character's origin in the world, in its units)");
    e.origin = Vec3d(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
  }
}

// The "simulation", "transfer" and "normal_maps" objects of `j` (named `prefix` in errors): a bake
// config's part1, or the settings a dataset and a baked model carry (DatasetBuildSettings::toJson).
void parseShapeSections(const Checker& c, const nlohmann::json& j, const std::string& prefix, DatasetBuildSettings& s) {
  const nlohmann::json sim = j.value("simulation", nlohmann::json::object());
  std::string p = prefix + ".simulation";
  c.onlyKeys(sim, p,
             {"preset",
              "vertices",
              "thickness",
              "transition_seconds",
              "settle_seconds",
              "frame_rate",
              "substeps",
              "iterations",
              "threads",
              "gravity",
              "limb_clearance",
              "attach_band",
              "equilibrium_tolerance",
              "equilibrium_seconds",
              "equilibrium_iterations",
              "retries",
              "final_projection",
              "check_poses",
              "source",
              "path",
              "space",
              "units_per_metre",
              "up_axis",
              "origin"});
  parseSimulationSource(c, sim, p, s);
  ClothSimSettings& cs = s.simulation;
  if (sim.contains("preset")) {
    try {
      cs.material = clothMaterialPreset(c.string(sim, "preset", "", p));
    } catch (const Error& e) {
      c.fail(p + ".preset", e.what());
    }
  }
  s.simulationVertices = size_t(c.number(sim, p, "vertices", 0, 2e6, double(s.simulationVertices), true));
  cs.thickness = float(c.number(sim, p, "thickness", 0, 0.05, cs.thickness));
  cs.transitionSeconds = float(c.number(sim, p, "transition_seconds", 0.05, 10, cs.transitionSeconds));
  cs.settleSeconds = float(c.number(sim, p, "settle_seconds", 0, 10, cs.settleSeconds));
  cs.frameRate = float(c.number(sim, p, "frame_rate", 5, 1000, cs.frameRate));
  cs.substeps = int(c.number(sim, p, "substeps", 1, 1000, cs.substeps, true));
  cs.iterations = int(c.number(sim, p, "iterations", 1, 1000, cs.iterations, true));
  s.threads = int(c.number(sim, p, "threads", 0, 1024, s.threads, true));
  // Gravity along -Y in m/s^2 (0 turns it off: see docs/baking.md for why a bake may need that).
  cs.gravity = Vec3f(0.f, -float(c.number(sim, p, "gravity", 0, 100, -cs.gravity.y())), 0.f);
  // Metres kept between a limb and the trunk (limb_clearance.hpp); 0 leaves the poses as recorded.
  s.limbClearance.clearance = float(c.number(sim, p, "limb_clearance", 0, 0.1, s.limbClearance.clearance));
  // The top band of the garment held on the body (share of its rest height; cloth_solver.hpp).
  cs.attachTopFraction = float(c.number(sim, p, "attach_band", 0, 0.5, cs.attachTopFraction));
  // The end condition (cloth_solver.hpp): frames at the goal pose until the residual (the unbalanced
  // share of gravity's load) is at most the tolerance, for at most equilibrium_seconds, with
  // equilibrium_iterations sweeps per substep (0: "iterations").
  cs.equilibriumTolerance = float(c.number(sim, p, "equilibrium_tolerance", 1e-6, 10, cs.equilibriumTolerance));
  cs.equilibriumSeconds = float(c.number(sim, p, "equilibrium_seconds", 0, 60, cs.equilibriumSeconds));
  cs.equilibriumIterations = int(c.number(sim, p, "equilibrium_iterations", 0, 1000, cs.equilibriumIterations, true));
  // Retries of a failed pose along a slower path (twice the substeps and transition each) before it is left out.
  cs.retries = int(c.number(sim, p, "retries", 0, 4, cs.retries, true));
  // Vertices left within the thickness of the body at the end are moved out along its normal.
  cs.finalProjection = c.boolean(sim, p, "final_projection", cs.finalProjection);
  // Poses sampled for the report's convergence and noise figures (simulation_quality.hpp; 0: none).
  s.quality.poses = size_t(c.number(sim, p, "check_poses", 0, 1000, double(s.quality.poses), true));
  try {
    cs.validate();
  } catch (const Error& e) {
    c.fail(p, e.what());
  }

  const nlohmann::json tr = j.value("transfer", nlohmann::json::object());
  p = prefix + ".transfer";
  c.onlyKeys(tr, p, {"smoothing_strength", "smoothing_iterations", "smoothing_weights"});
  LaplacianSmoothingSettings& ls = s.transfer.smoothing;
  ls.strength = float(c.number(tr, p, "smoothing_strength", 0, 1, ls.strength));
  ls.iterations = int(c.number(tr, p, "smoothing_iterations", 0, 1000, ls.iterations, true));
  const std::string weights = c.string(tr, "smoothing_weights", "cotangent", p);
  if (weights == "cotangent")
    ls.weights = LaplacianWeights::Cotangent;
  else if (weights == "uniform")
    ls.weights = LaplacianWeights::Uniform;
  else
    c.fail(p + ".smoothing_weights", "'" + weights + "' is not one of cotangent, uniform");

  const nlohmann::json nm = j.value("normal_maps", nlohmann::json::object());
  p = prefix + ".normal_maps";
  c.onlyKeys(nm, p, {"size", "max_distance", "dilation_rings", "bit_depth"});
  NormalMapBakeSettings& nb = s.transfer.normalMap;
  nb.width = nb.height = uint32_t(c.number(nm, p, "size", 4, 4096, nb.width, true));
  if (nb.width % 4 != 0) c.fail(p + ".size", "must be a multiple of 4 (the VQ codebook works on 4x4 blocks)");
  nb.maxDistance = float(c.number(nm, p, "max_distance", 1e-4, 1, nb.maxDistance));
  nb.dilationRings = int(c.number(nm, p, "dilation_rings", 0, 256, nb.dilationRings, true));
  s.normalMapBitDepth = uint32_t(c.number(nm, p, "bit_depth", 8, 16, s.normalMapBitDepth, true));
  if (s.normalMapBitDepth != 8 && s.normalMapBitDepth != 16) c.fail(p + ".bit_depth", "must be 8 or 16");
}

DatasetBuildSettings parsePart1(const Checker& c, const nlohmann::json& j, const std::filesystem::path& baseDir) {
  c.onlyKeys(j, "part1",
             {"character", "clips", "input_joints", "sampling", "thinning", "simulation", "transfer", "normal_maps",
              "preview", "holdout"});
  DatasetBuildSettings s;
  if (j.contains("character")) parseCharacter(c, j.at("character"), baseDir, s);
  if (!j.contains("clips")) c.fail("part1.clips", "is required (the animation to sample poses from)");
  s.clips = parseClipList(j.at("clips"), c.source.empty() ? "" : c.source + ": ", baseDir);
  s.inputJoints = c.strings(j, "part1", "input_joints", s.inputJoints);

  if (j.contains("holdout")) {
    // Whole subjects kept out of training, evaluated on evenly spaced frames of their clips.
    const nlohmann::json& h = j.at("holdout");
    const std::string p = "part1.holdout";
    c.onlyKeys(h, p, {"subjects", "poses"});
    s.holdoutSubjects = c.strings(h, p, "subjects", {});
    if (s.holdoutSubjects.empty()) c.fail(p + ".subjects", "is required (the subjects to hold out)");
    s.holdoutPoses = size_t(c.number(h, p, "poses", 1, 1e6, 200, true));
    std::set<std::string> held;
    for (const auto& subject : s.holdoutSubjects) held.insert(normaliseSubject(subject));
    std::set<std::string> seen;
    size_t training = 0;
    for (const ClipSource& clip : s.clips) {
      seen.insert(normaliseSubject(clip.subject));
      training += !held.count(normaliseSubject(clip.subject));
    }
    for (const auto& subject : s.holdoutSubjects)
      if (!seen.count(normaliseSubject(subject)))
        c.fail(p + ".subjects", "no clip of subject '" + subject + "' in part1.clips");
    if (training == 0) c.fail(p + ".subjects", "holds out every clip: nothing is left to train on");
  }

  const nlohmann::json sampling = j.value("sampling", nlohmann::json::object());
  std::string p = "part1.sampling";
  c.onlyKeys(sampling, p,
             {"characters", "seconds_per_character", "sample_rate", "mirror_odd_characters", "speed_jitter", "seed"});
  PoseSamplingOptions& so = s.sampling;
  so.characters = uint32_t(c.number(sampling, p, "characters", 1, 1000, so.characters, true));
  so.secondsPerCharacter = c.number(sampling, p, "seconds_per_character", 0, 86400, so.secondsPerCharacter);
  so.sampleRate = c.number(sampling, p, "sample_rate", 0, 1000, so.sampleRate);
  so.mirrorOddCharacters = c.boolean(sampling, p, "mirror_odd_characters", so.mirrorOddCharacters);
  so.speedJitter = float(c.number(sampling, p, "speed_jitter", 0, 0.9, so.speedJitter));
  so.seed = uint64_t(c.number(sampling, p, "seed", 0, 9.007199254740992e15, double(so.seed), true));

  if (!j.contains("thinning")) c.fail("part1.thinning", "is required: {\"tolerance\": t} or {\"target_poses\": n}");
  const nlohmann::json& thin = j.at("thinning");
  p = "part1.thinning";
  c.onlyKeys(thin, p, {"tolerance", "target_poses", "include_rest_pose"});
  if (thin.contains("tolerance") == thin.contains("target_poses"))
    c.fail(p, "give exactly one of \"tolerance\" and \"target_poses\"");
  s.thinningTolerance = float(c.number(thin, p, "tolerance", 1e-6, 100, 0));
  s.targetPoses = size_t(c.number(thin, p, "target_poses", 2, 1e6, 0, true));
  s.includeRestPose = c.boolean(thin, p, "include_rest_pose", s.includeRestPose);

  parseShapeSections(c, j, "part1", s);
  if (s.external.enabled()) {
    s.external.path = baseDir / s.external.path;
    std::error_code ec;
    if (!std::filesystem::exists(s.external.path, ec))
      c.fail("part1.simulation.path", s.external.path.string() + " does not exist (the external simulation's results)");
  }

  const nlohmann::json pv = j.value("preview", nlohmann::json::object());
  p = "part1.preview";
  c.onlyKeys(pv, p, {"poses", "size"});
  s.previewPoses = size_t(c.number(pv, p, "poses", 0, 64, double(s.previewPoses), true));
  s.previewSize = uint32_t(c.number(pv, p, "size", 16, 4096, s.previewSize, true));
  return s;
}
}  // namespace

PoseShapeSettings poseShapeSettingsFromJson(const nlohmann::json& datasetSettings, const std::string& what) {
  const Checker c{""};  // errors read "<what>.simulation.substeps: ..."
  if (!datasetSettings.is_object()) c.fail(what, "the dataset settings must be a JSON object");
  DatasetBuildSettings s;
  parseShapeSections(c, datasetSettings, what, s);
  // Settings recorded before cloth solver revision 7 have no end phase, retries or final projection:
  // the truth of such a model (swish replay --truth-every) is its own bake's solve, step for step.
  const nlohmann::json sim = datasetSettings.value("simulation", nlohmann::json::object());
  if (sim.is_object() && !sim.contains("equilibrium_seconds")) {
    s.simulation.equilibriumSeconds = 0.f;
    s.simulation.retries = 0;
    s.simulation.finalProjection = false;
  }
  return s.poseShape();
}

BakeConfig parseBakeConfig(const nlohmann::json& json, const std::string& source,
                           const std::filesystem::path& baseDir) {
  const Checker c{source};
  c.onlyKeys(json, "", {"name", "output", "work", "dataset", "part1", "train"});
  BakeConfig cfg;
  cfg.name = c.string(json, "name", "model");
  for (char ch : cfg.name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.'))
      c.fail("name", "'" + cfg.name + "' may only hold letters, digits, '_', '-' and '.' (it names files)");
  if (!json.contains("output")) c.fail("output", "is required (the folder for the model and the report)");
  cfg.output = baseDir / c.string(json, "output", "");
  cfg.work = json.contains("work") ? baseDir / c.string(json, "work", "") : cfg.output / "work";
  cfg.dataset = json.contains("dataset") ? baseDir / c.string(json, "dataset", "") : cfg.work / "dataset";
  if (json.contains("part1")) {
    if (!json.at("part1").is_object()) c.fail("part1", "must be a JSON object");
    cfg.part1 = parsePart1(c, json.at("part1"), baseDir);
  }
  const nlohmann::json train = json.value("train", nlohmann::json::object());
  c.onlyKeys(train, "train",
             {"mesh_components",
              "mesh_variance",
              "normal_code_dims",
              "database_size",
              "codebook_size",
              "vq_training_blocks",
              "vq_iterations",
              "hidden_layers",
              "hidden_width",
              "activation",
              "learning_rate",
              "batch_size",
              "max_epochs",
              "patience",
              "validation_fraction",
              "normal_code_weight",
              "mesh_weight_floor",
              "max_training_seconds",
              "test_fraction",
              "temporal_time_constant",
              "seed",
              "bc5_baseline",
              "input_joints"});
  BakeTrainSettings& t = cfg.train;
  const std::string p = "train";
  t.meshComponents = int(c.number(train, p, "mesh_components", 1, 4096, t.meshComponents, true));
  t.meshVariance = c.number(train, p, "mesh_variance", 0, 1, t.meshVariance);
  t.normalCodeDims = int(c.number(train, p, "normal_code_dims", 0, 256, t.normalCodeDims, true));
  t.databaseSize = int(c.number(train, p, "database_size", 1, 65536, t.databaseSize, true));
  t.vq.codebookSize = uint32_t(c.number(train, p, "codebook_size", 1, 65536, t.vq.codebookSize, true));
  t.vq.trainingBlocks = uint32_t(c.number(train, p, "vq_training_blocks", 0, 1e8, t.vq.trainingBlocks, true));
  t.vq.iterations = int(c.number(train, p, "vq_iterations", 0, 1000, t.vq.iterations, true));
  t.mlp.hiddenLayers = int(c.number(train, p, "hidden_layers", 0, 64, t.mlp.hiddenLayers, true));
  t.mlp.hiddenWidth = int(c.number(train, p, "hidden_width", 1, 4096, t.mlp.hiddenWidth, true));
  if (train.contains("activation")) {
    if (!train.at("activation").is_string()) c.fail("train.activation", "must be a string");
    try {
      t.mlp.activation = activationFromName(train.at("activation").get<std::string>());
    } catch (const Error& e) {
      c.fail("train.activation", e.what());
    }
    if (t.mlp.activation != Activation::Selu)
      c.fail("train.activation",
             "the .swish runtime evaluates SELU only; other activations are for experiments "
             "with the trainer, not for baked models");
  }
  t.mlp.learningRate = c.number(train, p, "learning_rate", 1e-7, 1.0, t.mlp.learningRate);
  t.mlp.batchSize = int(c.number(train, p, "batch_size", 1, 1 << 20, t.mlp.batchSize, true));
  t.mlp.maxEpochs = int(c.number(train, p, "max_epochs", 1, 1e7, t.mlp.maxEpochs, true));
  t.mlp.patience = int(c.number(train, p, "patience", 1, 1e7, t.mlp.patience, true));
  t.mlp.validationFraction = c.number(train, p, "validation_fraction", 0.01, 0.5, t.mlp.validationFraction);
  t.normalCodeWeight = c.number(train, p, "normal_code_weight", 0.001, 100, t.normalCodeWeight);
  t.meshWeightFloor = c.number(train, p, "mesh_weight_floor", 0, 1, t.meshWeightFloor);
  t.mlp.maxSeconds = c.number(train, p, "max_training_seconds", 0, 1e6, t.mlp.maxSeconds);
  t.testFraction = c.number(train, p, "test_fraction", 0, 0.49, t.testFraction);
  t.temporalTimeConstant = float(c.number(train, p, "temporal_time_constant", 0, 10, t.temporalTimeConstant));
  t.seed = uint64_t(c.number(train, p, "seed", 0, 9.007199254740992e15, double(t.seed), true));
  t.inputJoints = c.strings(train, p, "input_joints", t.inputJoints);
  if (train.contains("bc5_baseline")) {
    if (!train.at("bc5_baseline").is_boolean()) c.fail("train.bc5_baseline", "must be true or false");
    t.bc5Baseline = train.at("bc5_baseline").get<bool>();
  }
  return cfg;
}

BakeConfig loadBakeConfig(const std::filesystem::path& file) {
  return parseBakeConfig(readJsonFile(file, "bake config"), file.string(), file.parent_path());
}

}  // namespace swish::bake
