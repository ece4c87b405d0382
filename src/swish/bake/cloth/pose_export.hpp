#pragma once
// `swish bake CONFIG --export-poses DIR`: part 1's thinned pose list written out for a cloth tool the
// studio trusts (Marvelous Designer, Houdini Vellum, Maya nCloth), the paper's own way of working:
//
//   DIR/poses.bvh      the clip: per pose a transition from the A-pose (rest) to the pose, then a hold,
//   DIR/poses.glb      the same clip in glTF with the skinned body and the garment (rest pose) in it,
//   DIR/poses.json     the sidecar: per pose its id, first and target frame, the result file expected
//                      and its joint rotations; the pose list's digest, timing and mesh sizes,
//   DIR/body.obj       the body in the rest pose (the collider),
//   DIR/garment.obj    the garment to simulate in the rest pose: the simulation mesh, whose vertex
//                      order results may keep (else they are bound by closest point),
//   DIR/README.md      what to simulate and what to send back,
//   DIR/results/       where the results go: pose_<id>.obj (or .glb/.gltf/.fbx), rest.obj for a
//                      re-meshed garment; part1.simulation {"source": "external", "path": ...} reads it.
//
// The poses are the ones the built-in solver would simulate: root at rest, limbs turned out of the
// trunk (limb clearance); the clip's timing is the solver's (transition, settle, frame rate), so the
// result frame of a pose is the state ClothSolver::simulate keeps. Every file is written atomically.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "swish/bake/pipeline/part1_dataset.hpp"

namespace swish::bake {

struct PoseExportResult {
  size_t poses = 0;
  size_t clipFrames = 0;
  size_t simulationVertices = 0;
  std::vector<std::filesystem::path> files;  // written, in the order above
};

// Throws Error naming the file or setting (as buildDataset for the pose list; a folder that cannot be
// made or written).
PoseExportResult exportPoses(const DatasetBuildSettings& settings, const std::filesystem::path& dir,
                             const std::function<void(const std::string&)>& log = {});

// The export's result file name of pose `id` relative to DIR: "results/pose_000012.obj".
std::string exportedResultName(uint32_t id);

}  // namespace swish::bake
