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
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/cloth_solver.hpp"
#include "swish/bake/dataset_io.hpp"
#include "swish/bake/pose_sampling.hpp"
#include "swish/bake/pose_shape.hpp"
#include "swish/bake/pose_transfer.hpp"
#include "swish/bake/limb_clearance.hpp"
#include "swish/bake/simulation_mesh.hpp"
#include "swish/bake/simulation_quality.hpp"
#include "swish/io/joint_map.hpp"

namespace swish::bake {

struct ClipSource {
  std::filesystem::path file;
  io::JointNaming naming = io::JointNaming::Auto;
  std::vector<std::pair<std::string, std::string>> jointMap;  // clip joint -> character joint
  double framesPerSecond = 0.0;                               // resampling of key-framed formats; 0: the file's
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
  PoseSamplingOptions sampling;   // .joints is replaced by inputJoints

  // Thinning: exactly one of the two is > 0.
  float thinningTolerance = 0.f;
  size_t targetPoses = 0;
  // The character's rest pose (the A-pose every simulation starts from) joins the kept poses, last,
  // unless a kept pose is within the tolerance of it. Gameplay clips rarely hold the A-pose, and a
  // network that never saw it extrapolates there (arms among the inputs: several cm off); part 2
  // always trains on it (bake_training.cpp).
  bool includeRestPose = true;

  size_t simulationVertices = kDefaultSimulationVertices;  // 0: the welded game mesh, not subdivided
  ClothSimSettings simulation;
  // Limbs that pass into the trunk are turned out of it before simulating (limb_clearance.hpp);
  // clearance 0 turns this off.
  LimbClearanceSettings limbClearance;
  int threads = 0;                 // 0: all cores (TBB's default)
  // Convergence and noise measured on a seeded sample of the simulated poses (simulation_quality.hpp;
  // poses 0: not measured). Not part of the dataset's content: changing it rebuilds nothing.
  SimulationQualitySettings quality;

  PoseTransferSettings transfer;
  uint32_t normalMapBitDepth = 16;

  size_t previewPoses = 4;
  uint32_t previewSize = 384;

  // Every setting as JSON (for the dataset manifest and the rebuild check above).
  nlohmann::json toJson() const;
  // The settings of the one-pose simulation (pose_shape.hpp); poseShapeSettingsFromJson(toJson())
  // (bake_config.hpp) gives them back.
  PoseShapeSettings poseShape() const;
};

// The character the settings name: the embedded default, the default from a recipe file, or an
// imported glTF/FBX file. Throws Error naming the file on failure.
Character loadDatasetCharacter(const DatasetBuildSettings& settings);

struct DatasetBuildStep {
  std::string name;
  double seconds = 0.0;
};

struct DatasetBuildResult {
  size_t clipFrames = 0;           // frames over all clips
  size_t samples = 0;              // Theta samples before thinning
  size_t keptPoses = 0;            // after thinning (the rest pose included when it was added)
  bool restPoseAdded = false;      // the rest pose was appended to the thinned poses (its id: keptPoses - 1)
  size_t posesCorrected = 0;       // poses whose limbs (or one-surface head) were turned out of the body
  float maxCorrectionDegrees = 0.f;
  float maxTowardsRest = 0.f;      // head clearance: the largest fraction of the neck turned back to rest
  float tolerance = 0.f;           // the thinning tolerance used
  size_t simulationVertices = 0;
  size_t simulated = 0, simulationsReused = 0;
  size_t transferred = 0, transfersReused = 0;
  std::vector<FailedPose> failed;  // left out of the dataset, with the reason
  // The simulation's report (simulation_quality.hpp): failures per reason, retried poses, seconds per
  // pose per core, equilibrium residuals, and "quality" (convergence, noise) when measured.
  nlohmann::json simulationReport = nlohmann::json::object();
  bool rebuilt = false;            // settings had changed: the dataset's pose files were deleted first
  std::vector<DatasetBuildStep> steps;
  std::vector<std::filesystem::path> previews;
  nlohmann::json toJson() const;
};

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
// (simulation_quality.hpp). Run it on a garment and clips of one's own before a long bake.
nlohmann::json checkSimulation(const DatasetBuildSettings& settings, size_t poses, uint64_t seed,
                               const std::function<void(const std::string&)>& log = {});

}  // namespace swish::bake
