#pragma once
// The replay planner: from a scene and its outputs, the work of one frame, and what it leaves out and
// why (printed by `swish replay --plan` without running anything, and without a device). Its memory
// figures come from the GPU side itself (gpu/allocation_plan.hpp: the sizes GpuModel and
// FrameResources allocate with), so the memory it announces is the memory the replay engine allocates.
//
// Decisions:
//   - Normal-map lookup, VQ decode and blend, and the normals+tangents pass, run only when an output
//     wants normal maps or shading (outputs.render or outputs.normalMaps). Without them the model is
//     uploaded without its database (no codebook or indices on the GPU).
//   - Theta converts only the model's input joints to 6D; the other skeleton joints only enter FK.
//   - Characters wearing the same model are ONE batch: one MLP call, one dispatch per GPU pass.
//     A database map selected by several characters of a batch is decoded once per frame.
//   - An off-screen character (visible = false, or placed beyond cullDistance from the camera) gets no
//     pose evaluation, Theta, MLP, lookup, mesh or normal work at all: everything it would feed is
//     mesh or normal work.
//   - No GPU work at all when no output wants meshes (render, meshes, normalMaps all off).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/model/model.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct PlannerOptions {
  uint32_t framesInFlight = 1;  // the replay reads every frame back, so a second frame buys nothing
  bool leaveOut = true;         // false: the naive plan (every stage, every character), for comparison
  // The device lays the normal-map images over the blend's output (gpu::NormalMapImages::sharesTexels:
  // lavapipe does): no separate blended-maps buffer and no copy. Unknown without a device (`--plan`),
  // hence false by default: the plan's memory is then an upper bound.
  bool normalMapsShareTexels = false;
};

// One model's batch: its on-screen characters, in instance order.
struct PlannedBatch {
  std::string model;                 // SceneCharacter::model
  std::vector<uint32_t> characters;  // scene character indices, instance i = characters[i]
  bool tangentFrames = false;
  bool normalMaps = false;
  uint32_t thetaJoints = 0;  // joints converted to 6D per character
  uint32_t skeletonJoints = 0;
  uint32_t maxDecodedMaps = 0;  // distinct maps per frame at most: min(characters, database maps)
};

struct PlannedStage {
  std::string name;
  std::string device;               // "CPU" or "GPU"
  std::string batch;                // model of the batch ("" for all)
  uint32_t dispatchesPerFrame = 0;  // GPU dispatches at most (0 for CPU stages)
  uint64_t itemsPerFrame = 0;       // characters, joints, vertices or texels processed per frame
  std::string detail;
};

struct PlannedAllocation {
  std::string owner;  // model, or "<model> frame <slot>"
  std::string name;
  uint64_t bytes = 0;
  bool image = false;
};

struct LeftOutWork {
  std::string what;
  std::string why;
};

struct ReplayPlan {
  bool gpuWork = false;               // any deform at all
  std::vector<PlannedBatch> batches;  // only batches with at least one on-screen character
  std::vector<uint32_t> offScreen;    // scene character indices
  std::vector<PlannedStage> stages;
  std::vector<PlannedAllocation> allocations;
  std::vector<LeftOutWork> leftOut;

  uint32_t gpuDispatchesPerFrame() const;
  uint64_t gpuBytes() const;
  uint64_t rot6JointsPerFrame() const;
  const PlannedBatch* batchOf(const std::string& model) const;
  // Human-readable plan (what `--plan` prints).
  std::string describe() const;
  nlohmann::json toJson() const;
};

// models: every SceneCharacter::model of the scene -> the loaded model. Throws Error naming the scene
// and character when a model is missing from the map or a character's skeleton does not fit.
ReplayPlan planReplay(const runtime::Scene& scene, const std::map<std::string, const Model*>& models,
                      const PlannerOptions& options = {});

}  // namespace swish::replay
