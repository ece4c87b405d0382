#pragma once
// The `swish bake CONFIG` recipe: a JSON file, validated completely before any work starts. Unknown
// keys and out-of-range values are errors naming the key ("train.codebook_size: 70000 is outside
// 1..65536"). Paths are relative to the config file's folder.
//
//   {
//     "name": "default_jersey",          model file <output>/<name>.swish, report <output>/report/
//     "output": "out",
//     "work": "out/work",                intermediate files (default <output>/work): the per-pose
//                                        simulation results (<work>/simulation) and, unless "dataset"
//                                        says otherwise, the dataset (<work>/dataset). Bakes that share
//                                        it take turns at part 1 (<work>/part1.lock; the second waits and
//                                        names the first), their part 2s run side by side
//     "dataset": "out/work/dataset",     the dataset folder (bake/dataset/dataset_io.hpp): part 1 writes it,
//                                        part 2 reads it
//     "part1": {                         part 1 (bake/pipeline/part1_dataset.hpp); absent: the dataset must exist
//       "character": "default" | {"recipe": "recipe.json"} |
//                    {"file": "x.glb", "body_mesh": [..], "garment_mesh": [..], "simulation_mesh": [..]},
//       "clips": ["a.bvh", "mocap/cmu/*.bvh", {"file": "b.fbx", "naming": "auto|same|mixamo|unreal",
//                           "joint_map": {"clip joint": "character joint"} | "map.json", "fps": 0,
//                           "weight": 1}, {"index": "mocap/cmu-daz/index.tsv", "joint_map": ..}]
//                  (folders, globs, index files, weights, subjects: bake/poses/clip_list.hpp),
//       "input_joints": ["LowerBack", ...],
//       "holdout": {"subjects": ["8", "14"], "poses": 200},   whole subjects kept out of training and
//                  evaluated on `poses` frames evenly spaced over their clips (bake/report/subject_evaluation.hpp)
//       "sampling": {"characters", "seconds_per_character", "sample_rate", "mirror_odd_characters",
//                    "speed_jitter", "seed"},
//       "thinning": {"tolerance": 0.1} | {"target_poses": 200}, plus "include_rest_pose" (default true:
//                   the rest pose joins the kept poses and is always trained on) and "grow_from" (with
//                   target_poses: keep the poses, ids and simulations of the bake with target_poses
//                   grow_from, and add poses after them: part1_dataset.hpp),
//       "synthesis": {"joints": ["LeftShoulder", "RightShoulder"], "poses": 1000, "candidates" (0: 8 x poses),
//                     "extend" (0.25), "seed"}: poses whose named joints take rotations between and a little
//                     beyond two recorded samples', thinned against the recorded poses and added after them
//                     (bake/poses/pose_synthesis.hpp; absent: none),
//       "simulation": {"preset", "friction" (overrides the preset's, 0-2), "damping" (the preset's
//                      velocity damping in 1/s, overridden, 0-100), "vertices", "thickness",
//                      "transition_seconds", "settle_seconds",
//                      "frame_rate", "substeps", "iterations", "threads", "gravity" (m/s^2 along -Y),
//                      "limb_clearance" (m kept between limbs and trunk, 0: off; limb_clearance.hpp),
//                      "limb_garment_reach" (m: only the trunk this near the garment is kept clear, 0: all),
//                      "attach_band" (top share of the garment's height held on the body),
//                      "equilibrium_tolerance", "equilibrium_seconds", "equilibrium_iterations",
//                      "equilibrium_substeps" (the end condition: cloth_solver.hpp; substeps 0: the
//                      path's), "static_solve" (true: a Newton static solve
//                      instead, static_solve.hpp) with "static_tolerance", "static_iterations",
//                      "retries" (of a failed pose, slower each),
//                      "final_projection" (out of the body at the end), "carry": "skinning" (default) |
//                      "translation" (how the cloth follows the body between frames: cloth_solver.hpp),
//                      "retry_carries": ["skinning", "translation"] (default) | ["skinning"] (before
//                      session 24) | ["translation"] (the carries each retry tries in turn),
//                      "check_poses" (sampled for the report's convergence and noise, 0: none),

//                      "source": "solver" (default) | "external" with "path" (a folder of pose_<id>.obj/
//                      .glb/.gltf/.fbx results, or one multi-frame .glb/.gltf/.fbx) and "space":
//                      "character" (default) | "world" with "units_per_metre", "up_axis" (y|z), "origin"
//                      (external_simulation.hpp; `swish bake CONFIG --export-poses DIR` writes what
//                      the external tool needs)},
//       "transfer": {"smoothing_strength", "smoothing_iterations", "smoothing_weights",
//                    "unskin_min_singular_value" (0.01-1, default 0.2: core/skinning.hpp),
//                    "max_edge_strain" (0.5-1000, default 4: a game-mesh edge stretched more fails
//                    the pose as torn; transfer/pose_transfer.hpp),
//                    "reskin_min_singular_value" (0-0.5, default 0.4: where a corrected pose's vertex
//                    moves with its skinned rest position; pose_transfer.hpp),
//                    "cover_body_mm" (0-20, default 2: the game mesh kept this far outside the body
//                    where the simulation's cloth covers it; 0: off; transfer/body_cover.hpp)},
//       "normal_maps": {"size", "max_distance", "dilation_rings", "bit_depth"},
//       "preview": {"poses", "size"}
//     },
//     "train": {                         part 2 settings (every key optional; defaults in part2_training.hpp)
//       "mesh_components", "mesh_variance", "normal_code_dims", "database_size", "codebook_size",
//       "vq_training_blocks", "vq_iterations", "hidden_layers", "hidden_width", "activation",
//       "learning_rate", "weight_decay" (AdamW, 0: off),
//       "input_noise" (std of Gaussian noise on the standardised inputs in training, 0: off), "batch_size",
//       "max_epochs", "patience", "validation_fraction", "normal_code_weight" (the normal code's share of the MLP loss,
//       1: the mesh's), "mesh_weight_floor" (0..1, default 0: the mesh weights' loss follows the vertex error; a floor
//       shares that much of it evenly over the components), "max_training_seconds", "test_fraction",
//       "temporal_time_constant", "seed", "bc5_baseline", "anchor_calibration" ("strict", the default: the push-out's
//       anchors calibrated on the training poses; "none": every anchor keeps the margin; part2_training.hpp),
//       "anchor_margin_mm" (the push-out's margin, 0..50, default 2), "cover_anchors" (the third anchor set,
//       default off), "anchor_poses" ("training", the default: the slide and cover anchors fitted on the
//       training poses; "as_played", or {"from": "as_played", "frames": 400}: on the training pose nearest
//       each of about that many frames of part1's training clips as a game plays them; with "simulated":
//       true, on those frames' own simulations, which part 1 adds; part2_training.hpp),
//       "distill": {"poses" (required), "mix_share", "swap_probability", "neighbours"} (a kernel-ridge
//                  teacher's labels for synthetic poses beside the simulated ones; distillation.hpp),
//       "input_joints" (the network's Theta joints; absent:
//       part1.input_joints, the thinning joints;
//                       checked against the character before part 1 simulates anything)
//     }
//   }
// Files named in part1 (character, recipe, clips) must exist when the config is loaded.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/bake/pipeline/part2_training.hpp"

namespace swish::bake {

struct BakeConfig {
  std::string name = "model";
  std::filesystem::path output;
  std::filesystem::path work;
  std::filesystem::path dataset;
  std::optional<DatasetBuildSettings> part1;  // absent: the dataset folder must already exist
  BakeTrainSettings train;

  std::filesystem::path modelPath() const { return output / (name + ".swish"); }
  std::filesystem::path reportDir() const { return output / "report"; }
  std::filesystem::path simulationDir() const { return work / "simulation"; }
  std::filesystem::path previewDir() const { return reportDir() / "dataset_preview"; }
  // The held-out subjects' poses (part1.holdout): their own simulations and dataset.
  std::filesystem::path holdoutSimulationDir() const { return work / "simulation_holdout"; }
  std::filesystem::path holdoutDatasetDir() const { return work / "holdout_dataset"; }
  // The training clips' frames as played that the body anchors are fitted on (train.anchor_poses
  // "as_played" with "simulated": true): their own simulations and dataset.
  std::filesystem::path anchorFramesSimulationDir() const { return work / "simulation_anchor_frames"; }
  std::filesystem::path anchorFramesDatasetDir() const { return work / "anchor_frames_dataset"; }
  bool simulatesAnchorFrames() const { return part1 && train.anchorsAsPlayed && train.anchorFramesSimulated; }
};

// `source` names the config in error messages; `baseDir` resolves relative paths.
BakeConfig parseBakeConfig(const nlohmann::json& json, const std::string& source, const std::filesystem::path& baseDir);
BakeConfig loadBakeConfig(const std::filesystem::path& file);

// The pose-shape settings back from the JSON form DatasetBuildSettings::toJson writes (its
// "simulation", "transfer" and "normal_maps" objects, the same keys and ranges as a config's part1),
// which a dataset's part1_settings.json and a baked model's metadata ("dataset_settings") carry. Absent
// keys keep their defaults. Throws Error naming `what` and the key ("meta.simulation.substeps: ...")
// for an unknown key, a value of the wrong type or out of range, or an unknown cloth preset.
PoseShapeSettings poseShapeSettingsFromJson(const nlohmann::json& datasetSettings, const std::string& what);

}  // namespace swish::bake
