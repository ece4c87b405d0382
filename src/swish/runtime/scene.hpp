#pragma once
// A replay scene: which characters play, wearing which model, driven by which motion, standing where,
// over which frames, and which outputs are wanted. Plain data (no Vulkan, no I/O); scene_file.hpp reads
// it from JSON and documents the file format; replay/replay_plan.hpp turns it into the work of one frame.
//
// Positions are kept in double: a character may stand kilometres from the origin (open worlds), and
// the runtime computes everything relative to the character (float is precise there), applying the
// placement only at the very end (see ScenePlacement::apply).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/types.hpp"
#include "swish/runtime/level_planner.hpp"

namespace swish::runtime {

// The model name that stands for the embedded default model (assets/default) instead of a file.
inline constexpr const char* kDefaultModelName = "default";

// Where a character stands in the world: a rotation about +Y (yaw), then a translation.
struct ScenePlacement {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // metres
  double yawDegrees = 0.0;

  // Character space -> world, in double (precise at 1e4 m and beyond).
  Eigen::Vector3d apply(const Vec3f& characterPoint) const;
  Eigen::Matrix3d rotation() const;
};

// Motion from an animation clip file (BVH or anything io::readAnimationWithAssimp reads).
struct SceneClip {
  std::filesystem::path file;
  std::string clipName;            // empty: the file's (only) clip; else must match it
  double timeOffsetSeconds = 0.0;  // clip time at scene time 0 (wraps around the clip's length)
  double speed = 1.0;              // playback speed, > 0
  // The clip's joint map (io/joint_map.hpp's JSON form: pairs and chains), inline or read from
  // jointMapFile; null: the names are matched by convention. The replay parses it (io::parseJointMap).
  nlohmann::json jointMap;
  std::filesystem::path jointMapFile;  // empty: inline or none
};

struct SceneCharacter {
  std::string name;
  std::string model;                                // kDefaultModelName, or a .swish file (resolved path)
  std::optional<SceneClip> clip;                    // exactly one of clip / poseStream
  std::optional<std::filesystem::path> poseStream;  // a recorded pose stream (pose_stream format)
  ScenePlacement placement;
  bool visible = true;  // false: off screen, skips mesh and normal-map work
  // A quality level the scene fixes for this character (a name of its model's ladder, or an index), as a
  // host with its own LOD system would; empty: the level planner chooses (level_planner.hpp).
  std::string level;
};

// How the level planner (level_planner.hpp) spends the frame: all optional.
struct SceneLevels {
  std::optional<double> frameBudgetMs;    // GPU milliseconds per frame for all characters
  std::optional<double> tolerancePixels;  // cheapest level whose mean error on screen is within this
  double holdSeconds = 1.0;               // a character keeps a level at least this long after a change
};

// Outputs a scene asks for. What they need decides the work (replay/replay_plan.hpp):
//   render     a renderer consumes every frame: deformed meshes, normals+tangents, normal maps
//   meshes     per-frame glTF meshes (positions; with normals when render or normalMaps is on)
//   normalMaps per-frame PNG normal maps per character (needs the normal-map passes and tangents)
//   report     JSON + Markdown report with plots (always cheap: it reads what the frame produced)
struct SceneOutputs {
  std::filesystem::path directory = "replay-out";
  bool report = true;
  bool render = false;
  bool meshes = false;
  bool normalMaps = false;
  uint32_t gpuCheckEvery = 1;  // compare GPU outputs with the CPU reference on every Nth frame (>= 1)
};

// What the scene does with the body under the garment (both off unless the scene asks: a body showing
// through is a fault to see; a game scene, like the default football play, turns both on, as games do).
struct SceneBody {
  bool pushOut = false;      // keep the garment off the body: the push-out to each model's body anchors
  bool hideCovered = false;  // the preview render leaves out the body triangles the garment covers
};

struct Scene {
  std::string name;
  std::filesystem::path source;  // the scene file, for messages ("<built-in>" for code-made scenes)
  uint32_t firstFrame = 0;       // scene frames [firstFrame, firstFrame + frameCount)
  uint32_t frameCount = 1;
  double framesPerSecond = 30.0;
  Eigen::Vector3d camera = Eigen::Vector3d::Zero();  // the camera's position
  std::optional<Eigen::Vector3d> cameraTarget;       // where it looks; default: the characters' mean, 1 m up
  double cameraFovDegrees = 50.0;                    // vertical field of view
  double imageHeightPixels = 1080.0;                 // of the image the characters are drawn into
  SceneLevels levels;
  std::optional<double> cullDistance;  // metres from the camera; beyond it a character is off screen
  SceneBody body;
  SceneOutputs outputs;
  std::vector<SceneCharacter> characters;

  double timeOfFrame(uint32_t sceneFrame) const { return double(sceneFrame) / framesPerSecond; }
  // Whether character c gets mesh and normal work: visible, and (with a cull distance) its placement no
  // further than cullDistance from the camera. Culling looks at the placement, not the per-frame root
  // motion, so that the plan stays the same for every frame.
  bool onScreen(size_t c) const;
  // The camera as the level planner sees it (cameraTarget or its default filled in).
  LevelCamera levelCamera() const;
  // The level planner's settings from the scene: its camera, its "levels" (a budget or tolerance given
  // here, e.g. on the command line, replaces the scene's) and the hold in frames.
  LevelPlannerSettings levelPlannerSettings(std::optional<double> frameBudgetMs = std::nullopt,
                                            std::optional<double> tolerancePixels = std::nullopt) const;
  // Checks values (counts, ranges, names) and throws Error naming the scene and the field. Does not
  // touch files: scene_file.cpp checks those.
  void validate() const;
};

}  // namespace swish::runtime
