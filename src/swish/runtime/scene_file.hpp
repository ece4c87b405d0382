#pragma once
// The scene file (JSON) of `swish replay`. Validated completely before anything runs: an unknown key, a
// wrong type, a value out of range or a missing file is an Error naming the scene file, the JSON path
// (e.g. characters[3].model) and the problem.
//
// ============================================ Schema ============================================
// {
//   "name": "football play",                  string, optional (default: the file's stem)
//   "frames": {                               required
//     "start": 0,                             integer >= 0, optional (default 0): first scene frame
//     "count": 120,                           integer 1..10000000, required
//     "rate": 30                              number in (0, 1000], optional (default 30): frames per second
//   },
//   "camera": { "position": [0, 1.8, -40] },  optional; used by cullDistance
//   "cullDistance": 80,                       number > 0, optional: characters placed further than this
//                                             from the camera are off screen (no mesh/normal work)
//   "body": {                                 optional (defaults shown): the body under the garment
//     "pushOut": false,                       run the push-out to the models' body anchors (as
//                                             api::BatchOptions::pushOut; replay --push-out / --no-push-out)
//     "hideCovered": false                    the preview render leaves out the body triangles the
//                                             garment covers (as games do; replay --hide-covered-body /
//                                             --show-covered-body)
//   },
//   "outputs": {                              optional (defaults shown)
//     "directory": "replay-out",              string: relative to the scene file's folder
//     "report": true,                         JSON + Markdown report with SVG plots
//     "render": false,                        frames are for a renderer: meshes, tangents, normal maps
//     "meshes": false,                        per-frame glTF meshes
//     "normalMaps": false,                    per-frame PNG normal maps
//     "gpuCheckEvery": 1                      integer >= 1: GPU-vs-CPU-reference check every Nth frame
//   },
//   "characters": [                           required, at least one
//     {
//       "name": "QB",                         string, unique, required
//       "model": "default",                   "default" (the embedded model) or a .swish file, required
//       "animation": {                        one of "animation" / "poseStream" is required
//         "file": "/usr/share/assimp/models/BVH/01_01.bvh",   BVH (or any assimp animation)
//         "clip": "01_01",                    optional: must match the file's clip name
//         "timeOffset": 1.5,                  seconds into the clip at scene time 0 (wraps), default 0
//         "speed": 1.0,                       playback speed in (0, 100], default 1
//         "jointMap": "daz_to_cmu.json"       optional: the clip's joint map (io/joint_map.hpp), a file
//                                             or inline {"clip joint": "model joint" or [chain]}, for
//                                             clips whose joint names no convention matches
//       },
//       "poseStream": "qb_poses.json",        a recorded pose stream (replay/pose_stream.hpp)
//       "placement": {                        optional
//         "translation": [0, 0, 0],           metres, world space, |x| <= 1e7
//         "yawDegrees": 180                   rotation about +Y before the translation
//       },
//       "visible": true                       false: off screen (no mesh or normal-map work)
//     }
//   ]
// }
// Relative file paths are relative to the scene file's folder. Example: assets/scenes/football.json.
// =================================================================================================
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "swish/runtime/scene.hpp"

namespace swish::runtime {

// Parses and validates; `source` names the scene in errors and resolves relative paths (its folder).
// checkFiles: models, clips and pose streams must exist (the default model name is exempt).
Scene parseScene(const nlohmann::json& json, const std::filesystem::path& source, bool checkFiles = true);
// Reads the file (Error naming it when missing or not JSON, with the parser's line and column).
Scene loadScene(const std::filesystem::path& file, bool checkFiles = true);
// The scene back as JSON (paths as stored), for reports and tests.
nlohmann::json sceneToJson(const Scene& scene);

}  // namespace swish::runtime
