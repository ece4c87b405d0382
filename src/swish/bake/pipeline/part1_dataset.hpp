#pragma once
// Part 1 of `swish bake`: from a character and animation clips to the training dataset folder.
//   character (embedded default, a recipe file, or glTF/FBX) -> clips (BVH/glTF/FBX, retargeted)
//   -> pose samples (6D of the input joints) -> greedy thinning -> source cloth simulation per pose
//   (parallel, resumable: <work>/simulation/pose_*.clothsim) -> transfer + Laplacian smoothing +
//   normal-map bake per pose -> DatasetWriter (resumable: a pose is done when its file exists)
//   -> manifest (with the failed poses) -> preview images.
//
// The simulated shape is a function of the input joints' rotations only (Theta), so every pose is
// simulated and stored with the root joint at its rest rotation and rest translation: the character
// stands upright where the A-pose stands, whichever way the clip's root turned or walked. Gravity then
// acts the same way for equal Theta, which is what the regressor can learn.
//
// Resumability across changed settings: <dataset>/part1_settings.json records every setting that
// decides a pose's content (and the thinned pose list). When a re-run's settings differ, the dataset's
// pose files are deleted and rebuilt; simulated poses are reused only where their own fingerprint
// (ClothSolver setup + pose) still matches, so e.g. a new normal-map size re-runs no simulation.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/cloth/external_simulation.hpp"
#include "swish/bake/cloth/simulation_mesh.hpp"
#include "swish/bake/cloth/simulation_quality.hpp"
#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/bake/poses/limb_clearance.hpp"
#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/bake/poses/pose_synthesis.hpp"
#include "swish/bake/transfer/pose_transfer.hpp"
#include "swish/io/joint_map.hpp"

namespace swish::bake {

// One clip of the recipe (bake/poses/clip_list.hpp expands folders, globs and index files into these).
struct ClipSource {
  std::filesystem::path file;
  io::JointNaming naming = io::JointNaming::Auto;
  std::vector<std::pair<std::string, std::string>> jointMap;  // clip joint -> character joint
  std::vector<io::JointChain> jointChains;                    // character joints driven together
  double framesPerSecond = 0.0;                               // resampling of key-framed formats; 0: the file's
  double weight = 1.0;                                        // sampling density (pose_sampling.hpp)
  std::string subject;                                        // the performer (held-out subjects, reports)
  size_t expectedFrames = 0;                                  // an index file's frame count (0: unknown)
};

struct DatasetBuildSettings {
  // Character: the embedded default (both paths empty), the default built from a recipe file, or an
  // imported glTF/FBX file whose meshes are picked by name (empty lists: the importer's defaults).
  std::filesystem::path characterRecipe;
  std::filesystem::path characterFile;
  std::vector<std::string> bodyMeshNames, garmentMeshNames, simulationMeshNames;

  std::vector<ClipSource> clips;
  std::vector<std::string> inputJoints = defaultInputJointNames();
  // Joints a later step reads (part 2's train.input_joints), checked against the character with
  // inputJoints before any simulation; they do not enter the dataset or its fingerprint.
  std::vector<std::string> alsoRequiredJoints;
  PoseSamplingOptions sampling;  // .joints is replaced by inputJoints

  // Whole subjects kept out of training (part1.holdout): their clips are not sampled for the dataset;
  // the bake simulates `holdoutPoses` frames of them, evenly spaced over their clips, into a second
  // dataset (BakeConfig::holdoutDatasetDir) that part 2 evaluates the model on (subject_evaluation.hpp).
  std::vector<std::string> holdoutSubjects;
  size_t holdoutPoses = 0;
  // > 0: instead of sampling and thinning, this many frames evenly spaced over the clips (each clip
  // in proportion to its length, at least one, frame 0 skipped: the conversions put a reference
  // T-pose there). The held-out subjects' dataset is built this way: frames as a game plays them.
  size_t evenPoses = 0;

  // Thinning: exactly one of the two is > 0 (unless evenPoses is).
  float thinningTolerance = 0.f;
  size_t targetPoses = 0;
  // > 0 (with targetPoses, and smaller): grow the pose list a bake with targetPoses = growFrom chose
  // (part1.thinning.grow_from). Its poses, and its rest pose, keep their ids and so their simulations;
  // a second greedy pass at a smaller tolerance adds poses after them up to targetPoses
  // (pose_thinning.hpp). The result covers the samples as densely as a fresh thinning to targetPoses,
  // with other poses.
  size_t growFrom = 0;
  // Poses between and around the recorded ones (pose_synthesis.hpp): after the recorded poses (and the rest
  // pose), so their ids and simulations stay. Off unless joints and a count are given.
  PoseSynthesisSettings synthesis;
  // The character's rest pose (the A-pose every simulation starts from) joins the kept poses, last,
  // unless a kept pose is within the tolerance of it. Gameplay clips rarely hold the A-pose, and a
  // network that never saw it extrapolates there (arms among the inputs: several cm off); part 2
  // always trains on it (part2_training.cpp).
  bool includeRestPose = true;

  size_t simulationVertices = kDefaultSimulationVertices;  // 0: the welded game mesh, not subdivided
  ClothSimSettings simulation;
  // When enabled, the simulated shapes come from another tool's files (external_simulation.hpp)
  // instead of the solver; `simulation` then only times the exported clip (transition, settle, rate).
  ExternalSimulationSettings external;
  // Limbs that pass into the trunk are turned out of it before simulating (limb_clearance.hpp);
  // clearance 0 turns this off.
  LimbClearanceSettings limbClearance;
  int threads = 0;  // 0: all cores (TBB's default)
  // Convergence and noise measured on a seeded sample of the simulated poses (simulation_quality.hpp;
  // poses 0: not measured). Not part of the dataset's content: changing it rebuilds nothing.
  SimulationQualitySettings quality;

  PoseTransferSettings transfer;
  uint32_t normalMapBitDepth = 16;

  size_t previewPoses = 4;
  uint32_t previewSize = 384;

  // Not a recipe setting (not in toJson): nonzero when the simulations were made elsewhere, by the
  // array tasks of `swish bake --slurm` (swish/cluster/), for the pose list of this fingerprint
  // (DatasetPosePlan::fingerprint). buildDataset then simulates nothing: another pose list, or a pose
  // without its finished simulation file, is an error.
  uint64_t simulatedPoseList = 0;

  // Every setting as JSON (for the dataset manifest and the rebuild check above).
  nlohmann::json toJson() const;
  // The settings of the one-pose simulation (pose_shape.hpp); poseShapeSettingsFromJson(toJson())
  // (bake_config.hpp) gives them back.
  PoseShapeSettings poseShape() const;
};

// `count` frames evenly spaced over the clips (DatasetBuildSettings::evenPoses), as samples with
// origins only (no Theta values: nothing is thinned).
PoseSamples evenlySpacedFrames(const std::vector<AnimationClip>& clips, size_t count);

// Reads and retargets the clips onto `skeleton` in parallel (`threads` 0: all cores). Throws Error
// naming the first clip in list order that fails (missing, malformed, unmapped joints, a frame count
// other than its index file's), with the number of other failures. `log` gets one summary line (and a
// line per clip for short lists).
std::vector<AnimationClip> importClips(const std::vector<ClipSource>& sources, const Skeleton& skeleton,
                                       const std::vector<std::string>& requiredJoints, int threads,
                                       const std::function<void(const std::string&)>& log = {});

// The character the settings name: the embedded default, the default from a recipe file, or an
// imported glTF/FBX file. Throws Error naming the file on failure.
Character loadDatasetCharacter(const DatasetBuildSettings& settings);

struct DatasetBuildStep {
  std::string name;
  double seconds = 0.0;
};

struct DatasetBuildResult {
  size_t clipFrames = 0;        // frames over all clips
  size_t samples = 0;           // Theta samples before thinning
  size_t keptPoses = 0;         // after thinning (the rest pose included when it was added)
  bool restPoseAdded = false;   // the rest pose was appended to the thinned poses (after the first stage's)
  size_t synthesizedPoses = 0;  // of keptPoses, drawn by part1.synthesis (the last ones)
  size_t synthesisCandidates = 0;
  size_t posesCorrected = 0;  // poses whose limbs (or one-surface head) were turned out of the body
  float maxCorrectionDegrees = 0.f;
  size_t neckRangePoses = 0;  // poses whose neck chain the neck range turned back (limb_clearance.hpp)
  // Per root joint turned (limb clearance): in how many poses, by how much (mean and largest degrees).
  // Tells which of the body's limbs its clips put through the trunk (the mannequin's hanging arms).
  struct JointCorrections {
    size_t poses = 0;
    double meanDegrees = 0.0, maxDegrees = 0.0;
  };
  std::map<std::string, JointCorrections> correctionsByJoint;
  float maxTowardsRest = 0.f;  // head clearance: the largest fraction of the neck turned back to rest
  float tolerance = 0.f;       // the thinning tolerance used
  size_t simulationVertices = 0;
  size_t simulated = 0, simulationsReused = 0;
  size_t transferred = 0, transfersReused = 0;
  // Poses in the dataset with garment vertices whose skinning collapses under the simulated pose,
  // un-skinned damped (core/skinning.hpp): how many, the most such vertices in one pose, the smallest
  // singular value.
  size_t unskinDampedPoses = 0, unskinDampedMaxVertices = 0;
  float unskinSmallestSingularValue = 1.f;
  // part1.transfer.cover_body_mm (transfer/body_cover.hpp), over the poses transferred in this run: those
  // whose game mesh it moved, the vertices moved (all such poses), the largest move, the deepest body sample
  // through the game mesh before, the poses where some sample stayed through it, and those (and their
  // vertices) where the cover took back part of its moves so as not to tear an edge. bodyCover: in the
  // simulated pose; bodyCoverRecorded: again in the recorded pose, for poses that limb clearance changed
  // (pose_shape.hpp step 4: the skin the cloth covered round the turned-out arm stays covered).
  struct BodyCoverSummary {
    size_t poses = 0, vertices = 0, posesLeftThrough = 0;
    size_t posesHeld = 0, verticesHeld = 0;  // moves partly taken back so that no edge tears
    float largestShift = 0.f, deepest = 0.f;
    void add(const BodyCoverStats& s);
    nlohmann::json toJson() const;
  };
  BodyCoverSummary bodyCover, bodyCoverRecorded;
  std::vector<FailedPose> failed;  // left out of the dataset, with the reason
  // The simulation's report (cloth/simulation_quality.hpp): failures per reason, retried poses, seconds
  // per pose per core, equilibrium residuals, and "quality" (convergence, noise) when measured.
  nlohmann::json simulationReport = nlohmann::json::object();
  bool rebuilt = false;  // settings had changed: the dataset's pose files were deleted first
  std::vector<DatasetBuildStep> steps;
  std::vector<std::filesystem::path> previews;
  // Per pose id: where it came from ({"clip", "subject", "frame", "mirrored"}; the rest pose part 1
  // adds: {"clip": "rest pose"}). Also written to <dataset>/pose_origins.json.
  nlohmann::json origins;
  nlohmann::json toJson() const;
};

// Part 1 up to the simulation: character, clips, sampling, thinning, limb clearance and the solver.
// What a cluster bake computes once before it submits (the pose list its array tasks share), and
// what buildDataset starts with.
struct DatasetPosePlan {
  std::unique_ptr<const Character> character;  // the shapes below point into it
  std::vector<uint32_t> inputJoints;
  std::vector<Pose> recorded;    // the thinned poses as the clips hold them (the dataset keeps these)
  std::vector<Pose> toSimulate;  // the same with limbs turned out of the trunk: what is simulated
  std::unique_ptr<const PoseShapeSimulator> shapes;
  nlohmann::json settingsJson;  // <dataset>/part1_settings.json: settings + pose list digest
  DatasetBuildResult result;    // filled up to here (counts, corrections, steps)

  // The simulation file fingerprint of each pose (cloth/pose_driver.hpp), in pose id order.
  std::vector<uint64_t> poseFingerprints() const;
  // One number for the whole list: the settings, the pose list and every pose's simulation setup. Two
  // plans with the same fingerprint simulate the same poses into the same files.
  uint64_t fingerprint() const;
};

// Throws Error as buildDataset does for bad input, before any simulation. `clearOnly` (optional), given the
// thinned pose count, names the poses that limb clearance is run on (the others are simulated as recorded):
// for a tool that simulates a sample of them only (checkSimulation); a bake clears every pose.
DatasetPosePlan planDatasetPoses(const DatasetBuildSettings& settings,
                                 const std::function<void(const std::string&)>& log = {},
                                 const std::function<std::vector<uint32_t>(size_t)>& clearOnly = {});

// The poses part 1 simulates, before any simulation: the character, its clips sampled and thinned,
// the rest pose added, limb clearance applied. `swish bake --export-poses` writes these out for an
// external cloth tool (pose_export.hpp); buildDataset goes on to simulate them.
struct DatasetPoseList {
  std::unique_ptr<const Character> character;  // owned here: `shapes` points into it
  std::vector<uint32_t> inputJoints;
  std::vector<Pose> recorded;                        // what the dataset stores (the root canonical)
  std::vector<Pose> simulated;                       // recorded, limbs turned out of the trunk: what is simulated
  std::unique_ptr<const PoseShapeSimulator> shapes;  // simulation mesh, solver, transfer
  float thinningTolerance = 0.f;
  uint64_t digest = 0;  // of `simulated`: a different list means other pose ids
};
// planDatasetPoses in the shape the pose export reads. Fills res's pose counts and steps as buildDataset
// does. Throws Error as buildDataset does.
DatasetPoseList listDatasetPoses(const DatasetBuildSettings& settings, DatasetBuildResult& res,
                                 const std::function<void(const std::string&)>& log = {});

// Builds (or completes) the dataset folder `datasetDir`; per-pose simulation files go to
// `simulationDir`, preview images to `previewDir` (empty: none). `log` receives progress lines with
// the time left on the long steps. Throws Error (naming the file or setting) on bad input: a missing
// joint, a clip that does not map, a garment that starts inside the body... before the long steps.
DatasetBuildResult buildDataset(const DatasetBuildSettings& settings, const std::filesystem::path& datasetDir,
                                const std::filesystem::path& simulationDir, const std::filesystem::path& previewDir,
                                const std::function<void(const std::string&)>& log = {});

// `swish bake --check-simulation N CONFIG`: the source simulation's figures on a seeded sample of N of
// part 1's thinned poses, without building a dataset: failures per reason, retried poses, seconds per
// pose per core, equilibrium residuals, and convergence and noise on settings.quality.poses of them
// (cloth/simulation_quality.hpp). Run it on a garment and clips of one's own before a long bake.
nlohmann::json checkSimulation(const DatasetBuildSettings& settings, size_t poses, uint64_t seed,
                               const std::function<void(const std::string&)>& log = {});

}  // namespace swish::bake
