#include "swish/bake/pipeline/bake_config.hpp"

#include <cctype>
#include <set>

#include "swish/bake/poses/clip_list.hpp"
#include "swish/core/error.hpp"
#include "swish/files/json_file.hpp"
#include "swish/files/json_reader.hpp"

namespace swish::bake {

namespace {
// A file the bake reads: resolved against the config's folder, and it must exist now (before any work).
std::filesystem::path existingFile(const JsonReader& r, const std::filesystem::path& baseDir) {
  if (!r.value().is_string() || r.value().get<std::string>().empty())
    r.fail("must be a non-empty string (a file path)");
  std::filesystem::path f = baseDir / r.value().get<std::string>();
  if (!std::filesystem::is_regular_file(f)) r.fail("file " + f.string() + " does not exist");
  return f;
}

void parseCharacter(const JsonReader& v, const std::filesystem::path& baseDir, DatasetBuildSettings& s) {
  if (v.value().is_string()) {
    if (v.value().get<std::string>() != "default")
      v.fail("must be \"default\" or an object with \"file\" or \"recipe\"");
    return;
  }
  v.requireObject({"file", "recipe", "body_mesh", "garment_mesh", "simulation_mesh"});
  if (v.has("file") == v.has("recipe")) v.fail("give exactly one of \"file\" and \"recipe\"");
  if (v.has("recipe")) {
    s.characterRecipe = existingFile(v.child("recipe"), baseDir);
    if (v.value().size() > 1) v.fail("mesh names apply to an imported \"file\" only");
    return;
  }
  s.characterFile = existingFile(v.child("file"), baseDir);
  s.bodyMeshNames = v.strings("body_mesh", {});
  s.garmentMeshNames = v.strings("garment_mesh", {});
  s.simulationMeshNames = v.strings("simulation_mesh", {});
}

// part1.simulation "source": "solver" (the default) or "external" with "path" and the space keys
// (external_simulation.hpp). The path is resolved by parsePart1 (a dataset's or model's settings
// carry it as it was resolved then).
void parseSimulationSource(const JsonReader& sim, DatasetBuildSettings& s) {
  const std::string source = sim.nonEmptyString("source", "solver");
  if (source != "solver" && source != "external")
    sim.child("source").fail("'" + source + "' is not one of solver, external");
  const bool external = source == "external";
  for (const char* k : {"path", "space", "units_per_metre", "up_axis", "origin"})
    if (!external && sim.has(k)) sim.child(k).fail("applies to \"source\": \"external\" only");
  if (!external) return;
  if (!sim.has("path"))
    sim.child("path").fail(
        "is required with \"source\": \"external\" (the folder of pose_<id>.obj files, or one "
        "multi-frame .glb/.gltf/.fbx)");
  ExternalSimulationSettings& e = s.external;
  e.path = sim.nonEmptyString("path", "");
  const std::string space = sim.nonEmptyString("space", "character");
  if (space != "character" && space != "world")
    sim.child("space").fail("'" + space + "' is not one of character, world");
  e.worldSpace = space == "world";
  for (const char* k : {"units_per_metre", "up_axis", "origin"})
    if (!e.worldSpace && sim.has(k)) sim.child(k).fail("applies to \"space\": \"world\" only");
  e.unitsPerMetre = sim.number("units_per_metre", 1e-6, 1e6, 1.0);
  const std::string up = sim.nonEmptyString("up_axis", "y");
  if (up != "y" && up != "z") sim.child("up_axis").fail("'" + up + "' is not one of y, z");
  e.upAxis = up[0];
  if (sim.has("origin")) {
    const JsonReader origin = sim.child("origin");
    const nlohmann::json& o = origin.value();
    if (!o.is_array() || o.size() != 3 || !o[0].is_number() || !o[1].is_number() || !o[2].is_number())
      origin.fail("must be [x, y, z] (the character's origin in the world, in its units)");
    e.origin = Vec3d(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
  }
}

// The "simulation", "transfer" and "normal_maps" objects of `j` (errors name them from its path): a bake
// config's part1, or the settings a dataset and a baked model carry (DatasetBuildSettings::toJson).
void parseShapeSections(const JsonReader& j, DatasetBuildSettings& s) {
  const JsonReader sim = j.section("simulation", {"preset",
                                                  "friction",
                                                  "damping",
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
                                                  "limb_garment_reach",
                                                  "limb_neck_range",
                                                  "limb_one_surface",
                                                  "limb_turn_search",
                                                  "attach_band",
                                                  "equilibrium_tolerance",
                                                  "equilibrium_seconds",
                                                  "equilibrium_iterations",
                                                  "equilibrium_substeps",
                                                  "static_solve",
                                                  "static_tolerance",
                                                  "static_iterations",
                                                  "retries",
                                                  "final_projection",
                                                  "carry",
                                                  "retry_carries",
                                                  "safer_path_retries",
                                                  "check_poses",
                                                  "source",
                                                  "path",
                                                  "space",
                                                  "units_per_metre",
                                                  "up_axis",
                                                  "origin"});
  parseSimulationSource(sim, s);
  ClothSimSettings& cs = s.simulation;
  if (sim.has("preset")) {
    const JsonReader preset = sim.child("preset");
    const std::string name = preset.nonEmptyString();
    try {
      cs.material = clothMaterialPreset(name);
    } catch (const Error& e) {
      preset.fail(e.what());
    }
  }
  // The preset's Coulomb coefficient against the body, overridden (0: the cloth slides freely).
  cs.material.friction = float(sim.number("friction", 0, 2, cs.material.friction));
  // The preset's velocity damping (1/s), overridden (0: none; the path then keeps more of its motion).
  cs.material.damping = float(sim.number("damping", 0, 100, cs.material.damping));
  s.simulationVertices = size_t(sim.wholeNumber("vertices", 0, 2e6, double(s.simulationVertices)));
  cs.thickness = float(sim.number("thickness", 0, 0.05, cs.thickness));
  cs.transitionSeconds = float(sim.number("transition_seconds", 0.05, 10, cs.transitionSeconds));
  cs.settleSeconds = float(sim.number("settle_seconds", 0, 10, cs.settleSeconds));
  cs.frameRate = float(sim.number("frame_rate", 5, 1000, cs.frameRate));
  cs.substeps = int(sim.wholeNumber("substeps", 1, 1000, cs.substeps));
  cs.iterations = int(sim.wholeNumber("iterations", 1, 1000, cs.iterations));
  s.threads = int(sim.wholeNumber("threads", 0, 1024, s.threads));
  // Gravity along -Y in m/s^2 (0 turns it off: see docs/baking.md for why a bake may need that).
  cs.gravity = Vec3f(0.f, -float(sim.number("gravity", 0, 100, -cs.gravity.y())), 0.f);
  // Metres kept between a limb and the trunk (limb_clearance.hpp); 0 leaves the poses as recorded.
  s.limbClearance.clearance = float(sim.number("limb_clearance", 0, 0.1, s.limbClearance.clearance));
  // Only the trunk within this of the garment at rest is kept clear (limb_clearance.hpp); 0: all of it.
  s.limbClearance.garmentReach = float(sim.number("limb_garment_reach", 0, 1, s.limbClearance.garmentReach));
  // Degrees the neck chain may turn from rest, all its joints together (limb_clearance.hpp); 0: as recorded.
  s.limbClearance.neckRangeDegrees = float(sim.number("limb_neck_range", 0, 720, s.limbClearance.neckRangeDegrees));
  // A body that is one surface has its limbs' skin regions kept out of its trunk (limb_clearance.hpp).
  s.limbClearance.oneSurfaceLimbs = sim.boolean("limb_one_surface", s.limbClearance.oneSurfaceLimbs);
  // A limb the push's turn leaves inside is turned the least way that clears it (limb_clearance.hpp).
  s.limbClearance.turnSearch = sim.boolean("limb_turn_search", s.limbClearance.turnSearch);
  // The top band of the garment held on the body (share of its rest height; cloth_solver.hpp).
  cs.attachTopFraction = float(sim.number("attach_band", 0, 0.5, cs.attachTopFraction));
  // The end condition (cloth_solver.hpp): frames at the goal pose until the residual (the unbalanced
  // share of gravity's load) is at most the tolerance, for at most equilibrium_seconds, with
  // equilibrium_iterations sweeps per substep (0: "iterations").
  cs.equilibriumTolerance = float(sim.number("equilibrium_tolerance", 1e-6, 10, cs.equilibriumTolerance));
  cs.equilibriumSeconds = float(sim.number("equilibrium_seconds", 0, 60, cs.equilibriumSeconds));
  cs.equilibriumIterations = int(sim.wholeNumber("equilibrium_iterations", 0, 1000, cs.equilibriumIterations));
  cs.equilibriumSubsteps = int(sim.wholeNumber("equilibrium_substeps", 0, 10000, cs.equilibriumSubsteps));
  // Or the static solve instead (static_solve.hpp): Newton steps until the force residual is at most
  // static_tolerance, for at most static_iterations steps.
  cs.staticSolve = sim.boolean("static_solve", cs.staticSolve);
  cs.staticTolerance = float(sim.number("static_tolerance", 1e-6, 10, cs.staticTolerance));
  cs.staticIterations = int(sim.wholeNumber("static_iterations", 1, 1000, cs.staticIterations));
  // Retries of a failed pose along a slower path (twice the substeps and transition each) before it is left out.
  cs.retries = int(sim.wholeNumber("retries", 0, 4, cs.retries));
  // Vertices left within the thickness of the body at the end are moved out along its normal.
  cs.finalProjection = sim.boolean("final_projection", cs.finalProjection);
  // How the cloth follows the body from frame to frame (cloth_solver.hpp, ClothCarry).
  auto carryOf = [](const JsonReader& at, const std::string& c) {
    for (ClothCarry k : {ClothCarry::Skinning, ClothCarry::Translation, ClothCarry::DualQuaternion})
      if (c == clothCarryName(k)) return k;
    at.fail("'" + c + "' is not \"skinning\", \"translation\" or \"dual_quaternion\"");
  };
  cs.carry = carryOf(sim.child("carry"), sim.nonEmptyString("carry", "skinning"));
  // The carries a failed pose's retries try in turn (cloth_solver.hpp, ClothSimSettings::retryCarries).
  if (sim.has("retry_carries")) {
    const JsonReader list = sim.child("retry_carries");
    const std::vector<std::string> names = list.strings();
    if (names.size() > 3 || std::set<std::string>(names.begin(), names.end()).size() != names.size())
      list.fail("must name one to three different carries (\"skinning\", \"translation\", \"dual_quaternion\")");
    cs.retryCarries.clear();
    for (size_t i = 0; i < names.size(); ++i) cs.retryCarries.push_back(carryOf(list.at(i), names[i]));
  }
  // After the retries, the safer paths (cloth_solver.hpp, ClothSimSettings::saferPathRetries).
  cs.saferPathRetries = sim.boolean("safer_path_retries", cs.saferPathRetries);
  // Poses sampled for the report's convergence and noise figures (simulation_quality.hpp; 0: none).
  s.quality.poses = size_t(sim.wholeNumber("check_poses", 0, 1000, double(s.quality.poses)));
  try {
    cs.validate();
  } catch (const Error& e) {
    sim.fail(e.what());
  }

  const JsonReader tr = j.section(
      "transfer", {"smoothing_strength", "smoothing_iterations", "smoothing_weights", "unskin_min_singular_value",
                   "max_edge_strain", "reskin_min_singular_value", "cover_body_mm", "cover_recorded_pose"});
  LaplacianSmoothingSettings& ls = s.transfer.smoothing;
  ls.strength = float(tr.number("smoothing_strength", 0, 1, ls.strength));
  ls.iterations = int(tr.wholeNumber("smoothing_iterations", 0, 1000, ls.iterations));
  const std::string weights = tr.nonEmptyString("smoothing_weights", "cotangent");
  if (weights == "cotangent")
    ls.weights = LaplacianWeights::Cotangent;
  else if (weights == "uniform")
    ls.weights = LaplacianWeights::Uniform;
  else
    tr.child("smoothing_weights").fail("'" + weights + "' is not one of cotangent, uniform");
  UnskinSettings& un = s.transfer.unskin;
  un.minSingularValue = float(tr.number("unskin_min_singular_value", 0.01, 1, un.minSingularValue));
  s.transfer.maxEdgeStrain = float(tr.number("max_edge_strain", 0.5, 1000, s.transfer.maxEdgeStrain));
  // Where a corrected pose's vertex moves with its skinned rest position (pose_transfer.hpp; 0: nowhere).
  s.transfer.reskinMinSingularValue =
      float(tr.number("reskin_min_singular_value", 0, 0.5, s.transfer.reskinMinSingularValue));
  // How far outside the body the game mesh passes where the simulation covered it (body_cover.hpp; 0: off).
  s.transfer.cover.margin = float(tr.number("cover_body_mm", 0, 20, 1000.0 * s.transfer.cover.margin) / 1000.0);
  // And again in the recorded pose after limb clearance (pose_shape.hpp step 4).
  s.transfer.cover.recordedPose = tr.boolean("cover_recorded_pose", s.transfer.cover.recordedPose);

  const JsonReader nm = j.section("normal_maps", {"size", "max_distance", "dilation_rings", "bit_depth"});
  NormalMapBakeSettings& nb = s.transfer.normalMap;
  nb.width = nb.height = uint32_t(nm.wholeNumber("size", 4, 4096, nb.width));
  if (nb.width % 4 != 0) nm.child("size").fail("must be a multiple of 4 (the VQ codebook works on 4x4 blocks)");
  nb.maxDistance = float(nm.number("max_distance", 1e-4, 1, nb.maxDistance));
  nb.dilationRings = int(nm.wholeNumber("dilation_rings", 0, 256, nb.dilationRings));
  s.normalMapBitDepth = uint32_t(nm.wholeNumber("bit_depth", 8, 16, s.normalMapBitDepth));
  if (s.normalMapBitDepth != 8 && s.normalMapBitDepth != 16) nm.child("bit_depth").fail("must be 8 or 16");
}

DatasetBuildSettings parsePart1(const JsonReader& j, const std::filesystem::path& baseDir) {
  j.requireObject({"character", "clips", "input_joints", "sampling", "thinning", "synthesis", "simulation", "transfer",
                   "normal_maps", "preview", "holdout"});
  DatasetBuildSettings s;
  if (j.has("character")) parseCharacter(j.child("character"), baseDir, s);
  if (!j.has("clips")) j.child("clips").fail("is required (the animation to sample poses from)");
  s.clips = parseClipList(j.child("clips"), baseDir);
  s.inputJoints = j.strings("input_joints", s.inputJoints);

  if (j.has("holdout")) {
    // Whole subjects kept out of training, evaluated on evenly spaced frames of their clips.
    const JsonReader h = j.child("holdout");
    h.requireObject({"subjects", "poses"});
    s.holdoutSubjects = h.strings("subjects", {});
    if (s.holdoutSubjects.empty()) h.child("subjects").fail("is required (the subjects to hold out)");
    s.holdoutPoses = size_t(h.wholeNumber("poses", 1, 1e6, 200));
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
        h.child("subjects").fail("no clip of subject '" + subject + "' in part1.clips");
    if (training == 0) h.child("subjects").fail("holds out every clip: nothing is left to train on");
  }

  const JsonReader sampling = j.section("sampling", {"characters", "seconds_per_character", "sample_rate",
                                                     "mirror_odd_characters", "speed_jitter", "seed"});
  PoseSamplingOptions& so = s.sampling;
  so.characters = uint32_t(sampling.wholeNumber("characters", 1, 1000, so.characters));
  so.secondsPerCharacter = sampling.number("seconds_per_character", 0, 86400, so.secondsPerCharacter);
  so.sampleRate = sampling.number("sample_rate", 0, 1000, so.sampleRate);
  so.mirrorOddCharacters = sampling.boolean("mirror_odd_characters", so.mirrorOddCharacters);
  so.speedJitter = float(sampling.number("speed_jitter", 0, 0.9, so.speedJitter));
  so.seed = uint64_t(sampling.wholeNumber("seed", 0, 9.007199254740992e15, double(so.seed)));

  if (!j.has("thinning")) j.child("thinning").fail("is required: {\"tolerance\": t} or {\"target_poses\": n}");
  const JsonReader thin = j.child("thinning");
  thin.requireObject({"tolerance", "target_poses", "grow_from", "include_rest_pose"});
  if (thin.has("tolerance") == thin.has("target_poses"))
    thin.fail("give exactly one of \"tolerance\" and \"target_poses\"");
  s.thinningTolerance = float(thin.number("tolerance", 1e-6, 100, 0));
  s.targetPoses = size_t(thin.wholeNumber("target_poses", 2, 1e6, 0));
  s.includeRestPose = thin.boolean("include_rest_pose", s.includeRestPose);
  if (thin.has("grow_from")) {
    if (s.targetPoses == 0) thin.child("grow_from").fail("needs \"target_poses\" (the count to grow to)");
    s.growFrom = size_t(thin.wholeNumber("grow_from", 2, 1e6, 0));
    if (s.growFrom >= s.targetPoses)
      thin.child("grow_from")
          .fail("is " + std::to_string(s.growFrom) + ", not below target_poses (" + std::to_string(s.targetPoses) +
                "): nothing to grow");
  }

  if (j.has("synthesis")) {
    // Poses between the subjects (pose_synthesis.hpp).
    const JsonReader syn = j.child("synthesis");
    syn.requireObject({"joints", "poses", "candidates", "extend", "seed"});
    PoseSynthesisSettings& ps = s.synthesis;
    ps.joints = syn.strings("joints", {});
    if (ps.joints.empty()) syn.child("joints").fail("is required (the joints whose rotations are redrawn)");
    if (!syn.has("poses")) syn.child("poses").fail("is required (how many synthesized poses to add)");
    ps.poses = size_t(syn.wholeNumber("poses", 1, 1e6, 0));
    ps.candidates = size_t(syn.wholeNumber("candidates", 0, 1e8, 0));
    if (ps.candidates != 0 && ps.candidates < ps.poses)
      syn.child("candidates")
          .fail("is " + std::to_string(ps.candidates) + ", fewer than the " + std::to_string(ps.poses) +
                " poses to add");
    ps.extend = float(syn.number("extend", 0, 1, ps.extend));
    ps.seed = uint64_t(syn.wholeNumber("seed", 0, 9.007199254740992e15, double(ps.seed)));
  }

  parseShapeSections(j, s);
  if (s.external.enabled()) {
    s.external.path = baseDir / s.external.path;
    std::error_code ec;
    if (!std::filesystem::exists(s.external.path, ec))
      j.child("simulation")
          .child("path")
          .fail(s.external.path.string() + " does not exist (the external simulation's results)");
  }

  const JsonReader pv = j.section("preview", {"poses", "size"});
  s.previewPoses = size_t(pv.wholeNumber("poses", 0, 64, double(s.previewPoses)));
  s.previewSize = uint32_t(pv.wholeNumber("size", 16, 4096, s.previewSize));
  return s;
}
}  // namespace

PoseShapeSettings poseShapeSettingsFromJson(const nlohmann::json& datasetSettings, const std::string& what) {
  const JsonReader settings(datasetSettings, "", what);  // errors read "<what>.simulation.substeps: ..."
  if (!datasetSettings.is_object()) settings.fail("the dataset settings must be a JSON object");
  DatasetBuildSettings s;
  parseShapeSections(settings, s);
  // Settings recorded before cloth solver revision 7 have no end phase, retries or final projection:
  // the truth of such a model (swish replay --truth-every) is its own bake's solve, step for step.
  const nlohmann::json sim = datasetSettings.value("simulation", nlohmann::json::object());
  if (sim.is_object() && !sim.contains("equilibrium_seconds")) {
    s.simulation.equilibriumSeconds = 0.f;
    s.simulation.retries = 0;
    s.simulation.finalProjection = false;
  }
  // Settings recorded before the limb clearance looked only under the garment kept the whole trunk clear.
  if (sim.is_object() && !sim.contains("limb_garment_reach")) s.limbClearance.garmentReach = 0.f;
  // Settings recorded before the neck range left the neck as recorded.
  if (sim.is_object() && !sim.contains("limb_neck_range")) s.limbClearance.neckRangeDegrees = 0.f;
  // Settings recorded before one-surface bodies had limbs left those bodies' limbs as recorded.
  if (sim.is_object() && !sim.contains("limb_one_surface")) s.limbClearance.oneSurfaceLimbs = false;
  // Settings recorded before the turn search left a limb the push's turn could not clear inside.
  if (sim.is_object() && !sim.contains("limb_turn_search")) s.limbClearance.turnSearch = false;
  // Settings recorded before the carry was a setting carried the cloth by its skinning.
  if (sim.is_object() && !sim.contains("carry")) s.simulation.carry = ClothCarry::Skinning;
  // Settings recorded before the retries had their own carries retried with the skinning one.
  if (sim.is_object() && !sim.contains("retry_carries")) s.simulation.retryCarries = {ClothCarry::Skinning};
  // Settings recorded before the safer-path retries left a pose out after the retries above.
  if (sim.is_object() && !sim.contains("safer_path_retries")) s.simulation.saferPathRetries = false;
  // Settings recorded before it carried every corrected vertex through pre-skin space.
  const nlohmann::json tr = datasetSettings.value("transfer", nlohmann::json::object());
  if (tr.is_object() && !tr.contains("reskin_min_singular_value")) s.transfer.reskinMinSingularValue = 0.f;
  // Settings recorded before the game mesh was kept over the body stored it as transferred.
  if (tr.is_object() && !tr.contains("cover_body_mm")) s.transfer.cover.margin = 0.f;
  // Settings recorded before the cover ran in the recorded pose too kept it to the simulated one.
  if (tr.is_object() && !tr.contains("cover_recorded_pose")) s.transfer.cover.recordedPose = false;
  return s.poseShape();
}

BakeConfig parseBakeConfig(const nlohmann::json& json, const std::string& source,
                           const std::filesystem::path& baseDir) {
  const JsonReader root(json, source);
  root.requireObject({"name", "output", "work", "dataset", "part1", "train"});
  BakeConfig cfg;
  cfg.name = root.nonEmptyString("name", "model");
  for (char ch : cfg.name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.'))
      root.child("name").fail("'" + cfg.name + "' may only hold letters, digits, '_', '-' and '.' (it names files)");
  if (!root.has("output")) root.child("output").fail("is required (the folder for the model and the report)");
  cfg.output = baseDir / root.nonEmptyString("output", "");
  cfg.work = root.has("work") ? baseDir / root.nonEmptyString("work", "") : cfg.output / "work";
  cfg.dataset = root.has("dataset") ? baseDir / root.nonEmptyString("dataset", "") : cfg.work / "dataset";
  if (root.has("part1")) cfg.part1 = parsePart1(root.child("part1"), baseDir);
  const JsonReader train = root.section("train", {"mesh_components",
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
                                                  "weight_decay",
                                                  "input_noise",
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
                                                  "input_joints",
                                                  "anchor_calibration",
                                                  "anchor_margin_mm",
                                                  "cover_anchors",
                                                  "anchor_poses",
                                                  "root_gravity",
                                                  "distill"});
  BakeTrainSettings& t = cfg.train;
  t.meshComponents = int(train.wholeNumber("mesh_components", 1, 4096, t.meshComponents));
  t.meshVariance = train.number("mesh_variance", 0, 1, t.meshVariance);
  t.normalCodeDims = int(train.wholeNumber("normal_code_dims", 0, 256, t.normalCodeDims));
  t.databaseSize = int(train.wholeNumber("database_size", 1, 65536, t.databaseSize));
  t.vq.codebookSize = uint32_t(train.wholeNumber("codebook_size", 1, 65536, t.vq.codebookSize));
  t.vq.trainingBlocks = uint32_t(train.wholeNumber("vq_training_blocks", 0, 1e8, t.vq.trainingBlocks));
  t.vq.iterations = int(train.wholeNumber("vq_iterations", 0, 1000, t.vq.iterations));
  t.mlp.hiddenLayers = int(train.wholeNumber("hidden_layers", 0, 64, t.mlp.hiddenLayers));
  t.mlp.hiddenWidth = int(train.wholeNumber("hidden_width", 1, 4096, t.mlp.hiddenWidth));
  if (train.has("activation")) {
    const JsonReader activation = train.child("activation");
    const std::string name = activation.string();
    try {
      t.mlp.activation = activationFromName(name);
    } catch (const Error& e) {
      activation.fail(e.what());
    }
    if (t.mlp.activation != Activation::Selu)
      activation.fail(
          "the .swish runtime evaluates SELU only; other activations are for experiments "
          "with the trainer, not for baked models");
  }
  t.mlp.learningRate = train.number("learning_rate", 1e-7, 1.0, t.mlp.learningRate);
  t.mlp.weightDecay = train.number("weight_decay", 0, 100, t.mlp.weightDecay);
  t.mlp.inputNoise = train.number("input_noise", 0, 10, t.mlp.inputNoise);
  t.mlp.batchSize = int(train.wholeNumber("batch_size", 1, 1 << 20, t.mlp.batchSize));
  t.mlp.maxEpochs = int(train.wholeNumber("max_epochs", 1, 1e7, t.mlp.maxEpochs));
  t.mlp.patience = int(train.wholeNumber("patience", 1, 1e7, t.mlp.patience));
  t.mlp.validationFraction = train.number("validation_fraction", 0.01, 0.5, t.mlp.validationFraction);
  t.normalCodeWeight = train.number("normal_code_weight", 0.001, 100, t.normalCodeWeight);
  t.meshWeightFloor = train.number("mesh_weight_floor", 0, 1, t.meshWeightFloor);
  t.mlp.maxSeconds = train.number("max_training_seconds", 0, 1e6, t.mlp.maxSeconds);
  t.testFraction = train.number("test_fraction", 0, 0.49, t.testFraction);
  t.temporalTimeConstant = float(train.number("temporal_time_constant", 0, 10, t.temporalTimeConstant));
  t.seed = uint64_t(train.wholeNumber("seed", 0, 9.007199254740992e15, double(t.seed)));
  t.inputJoints = train.strings("input_joints", t.inputJoints);
  t.rootGravity = train.boolean("root_gravity", t.rootGravity);
  t.bc5Baseline = train.boolean("bc5_baseline", t.bc5Baseline);
  if (train.has("anchor_calibration")) {
    const JsonReader c = train.child("anchor_calibration");
    const std::string v = c.string();
    if (v != "strict" && v != "none") c.fail("must be \"strict\" or \"none\"");
    t.calibrateAnchors = v == "strict";
  }
  t.anchorMargin = float(train.number("anchor_margin_mm", 0, 50, 1000.0 * t.anchorMargin) / 1000.0);
  t.coverAnchors = train.boolean("cover_anchors", t.coverAnchors);
  if (train.has("anchor_poses")) {
    // "training" or "as_played", or {"from": one of those, "frames": N, "simulated": bool}
    // (BakeTrainSettings::anchorsAsPlayed).
    const JsonReader a = train.child("anchor_poses");
    const bool object = a.value().is_object();
    if (object) a.requireObject({"from", "frames", "simulated"});
    const JsonReader from = object ? a.required("from") : a;
    const std::string v = from.string();
    if (v != "training" && v != "as_played") from.fail("must be \"training\" or \"as_played\"");
    t.anchorsAsPlayed = v == "as_played";
    if (object) {
      t.anchorFramesAsPlayed = size_t(a.wholeNumber("frames", 1, 100000, double(t.anchorFramesAsPlayed)));
      t.anchorFramesSimulated = a.boolean("simulated", false);
      if (t.anchorFramesSimulated && !t.anchorsAsPlayed)
        a.child("simulated").fail("simulates frames as played: it needs \"from\": \"as_played\"");
    }
    if (t.anchorsAsPlayed && !cfg.part1)
      a.fail("\"as_played\" reads frames of part1.clips, and this recipe has no part1 section");
  }
  if (train.has("distill")) {
    // The kernel-ridge teacher's synthetic poses (distillation.hpp).
    const JsonReader d = train.child("distill");
    d.requireObject({"poses", "mix_share", "swap_probability", "neighbours"});
    if (!d.has("poses")) d.child("poses").fail("is required (how many synthetic poses the teacher labels)");
    t.distill.poses = size_t(d.wholeNumber("poses", 1, 1e6, 0));
    t.distill.mixShare = d.number("mix_share", 0, 1, t.distill.mixShare);
    t.distill.swapProbability = d.number("swap_probability", 0.01, 1, t.distill.swapProbability);
    t.distill.neighbours = int(d.wholeNumber("neighbours", 1, 1000, t.distill.neighbours));
  }
  return cfg;
}

BakeConfig loadBakeConfig(const std::filesystem::path& file) {
  return parseBakeConfig(readJsonFile(file, "bake config"), file.string(), file.parent_path());
}

}  // namespace swish::bake
