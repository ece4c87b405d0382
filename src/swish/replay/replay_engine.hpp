#pragma once
// The replay frame loop: for every scene frame, per model batch (replay_plan.hpp), on the CPU the poses
// (CharacterMotion), forward kinematics and skinning matrices, Theta, the MLP, the nearest-code lookup
// and temporal filter; then the GPU passes of every batch recorded into one command buffer, submitted
// and waited on. Per-stage times come from CPU clocks and GPU timestamps.
//
// Far from the origin: everything is computed in CHARACTER space (skinning matrices, deformed meshes,
// normals); the placement (ScenePlacement, double precision) is applied only to what leaves the
// engine (world positions of reports and exported meshes). A character at 1e4 m therefore gets
// bitwise the local mesh it gets at the origin.
//
// Errors measured: on every outputs.gpuCheckEvery-th frame, the GPU outputs of that frame against the
// CPU reference (runtime::referenceFrame) fed the same inputs and the GPU's previous normal maps:
// positions (mm), normals and tangents (degrees), normal maps (snorm16 steps), per character.
// Penetration (ReplayOptions::penetrationEvery): the garment against the body the model was baked on
// (rebuilt as the truth rebuilds it), per character per measured frame, before and after the push-out,
// on the CPU reference's positions; outside the timed stages.
// Ground truth (ReplayOptions::truth, `--truth-every N`; truth_simulation.hpp): on every Nth frame each
// on-screen character's pose is simulated by the bake's source simulation and the frame's GPU output
// is measured against it: per-vertex error (mm) and normal-map angular error (degrees), per character
// and overall. The simulations of a frame run after it, outside the timed stages, in parallel (TBB;
// several truth frames are gathered before they run), and each result lands in its own slot, so the
// figures do not depend on the schedule. A model whose bake character cannot be rebuilt gets no
// truth; ReplayResult::truthNote says why.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "swish/bake/report/penetration.hpp"
#include "swish/gpu/context.hpp"
#include "swish/replay/character_motion.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_plan.hpp"
#include "swish/replay/truth_simulation.hpp"
#include "swish/runtime/level_planner.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct ReplayOptions {
  gpu::ContextOptions device;
  gpu::Context* context = nullptr;  // use this device instead of creating one (tests, hosts)
  TruthOptions truth;               // truth.every 0: none; N: ground truth on every Nth frame
  bool pushOut = false;             // the run time's push-out to the body anchors (models that have them; --push-out)
  bool noveltyGuard = true;         // apply the models' novelty guards (measured either way; --no-guard)
  // Penetration of the garment into the body it was baked on (the CPU reference's positions, with and
  // without the push-out) on every Nth frame; 0: not measured.
  uint32_t penetrationEvery =
      30;  // the CPU measure poses a body collider per character: every frame would dwarf the replay
  // Quality levels (runtime/level_planner.hpp): overrides of the scene's "levels" (nullopt: the scene's).
  std::optional<double> frameBudgetMs;
  std::optional<double> tolerancePixels;
  std::string fixedLevel;  // every character at this level of its model's ladder (name or index); empty: planned
  std::function<void(uint32_t framesDone, uint32_t framesTotal)> progress;
  // Truth simulations done of those planned (called from worker threads, one call at a time).
  std::function<void(uint32_t posesDone, uint32_t posesTotal)> truthProgress;
  // Called after each frame with its GPU outputs read back (local, character space), per on-screen
  // character in plan order; only on frames where outputs are read back (checks, meshes, normalMaps).
  std::function<void(uint32_t sceneFrame, uint32_t character, const runtime::ReferenceFrameOutputs& batchOutputs,
                     uint32_t instance)>
      onCharacterOutput;
};

// Milliseconds; NaN where a stage did not run.
struct FrameTimes {
  double pose = 0, theta = 0, mlp = 0, novelty = 0, lookup = 0, record = 0;  // CPU stages (record: inputs + commands)
  double gpuWait = 0;                                                        // submit -> fence, wall clock
  double gpuDeform = 0, gpuTangents = 0, gpuDecode = 0, gpuBlend = 0, gpuTotal = 0;  // GPU timestamps
  double cpuTotal() const { return pose + theta + mlp + novelty + lookup + record; }
};

struct CharacterCheck {
  uint32_t character = 0;
  double maxPositionErrorMm = 0;
  double maxNormalErrorDeg = 0, maxTangentErrorDeg = 0;
  int maxMapErrorSteps = 0;  // snorm16 steps
  bool ok = true;
};

// One character's penetration on one frame (bake/report/penetration.hpp): the model's reconstruction as it
// comes out of skinning, and after the push-out (when the model has body anchors and it is on).
struct CharacterPenetration {
  uint32_t character = 0;
  bake::PenetrationStats model;
  bool pushedMeasured = false;
  bake::PenetrationStats pushed;
};

// One character's novelty on one frame (runtime/novelty_guard.hpp): how far its pose is from the
// model's training poses, the blend towards the mean shape the guard applied, and whether it is above
// the model's flag threshold.
struct CharacterNovelty {
  uint32_t character = 0;
  float novelty = 0, blend = 0;
  bool flagged = false;
};

// One model's quality ladder in the replay, and the error of every level against the ground truth of
// the frames with truth (every level reconstructed on the CPU from the same network output).
struct LevelTruth {
  uint32_t samples = 0;  // vertex distances pooled (vertices x measured character frames)
  double meanMm = 0, p95Mm = 0, maxMm = 0;
};
struct ModelLevels {
  std::string model;
  runtime::QualityLadder ladder;
  std::vector<double> calibratedMsPerCharacter;  // per level: the GPU ms one character adds (empty: not calibrated)
  std::vector<LevelTruth> truth;                 // per level (empty without truth)
};

struct PenetrationSummary {
  bake::PenetrationPool model, pushed;
  bool pushedMeasured = false;
};

struct FrameRecord {
  uint32_t frame = 0;
  FrameTimes times;
  uint32_t gpuDispatches = 0;  // compute dispatches recorded (the plan's gpuDispatchesPerFrame at most)
  bool checked = false;
  std::vector<CharacterCheck> checks;  // when checked
  uint32_t poseIssues = 0;
  bool truthFrame = false;                        // on the --truth-every grid, with a model that has truth
  std::vector<CharacterTruth> truth;              // when truthFrame: per on-screen character with truth, plan order
  std::vector<CharacterPenetration> penetration;  // per on-screen character with a body, plan order (measured frames)
  std::vector<CharacterNovelty> novelty;          // per on-screen character of a model with a guard, plan order
  std::vector<uint8_t> levels;                    // per on-screen character, plan order: its quality level
  uint32_t levelChanges = 0;                      // characters whose level changed this frame
  double predictedGpuMs = 0;                      // the level planner's prediction (NaN: no costs)
  double costScale = 0;                           // measured over calibrated GPU time after this frame (NaN: none)
  double weightedErrorMm = 0;                     // screen-weighted ladder error of the chosen levels (NaN: unmeasured)
  double fullErrorMm = 0;                         // the same at full quality
  double maxPositionErrorMm() const;
  double maxNormalErrorDeg() const;
  int maxMapErrorSteps() const;
};

// Tolerances of the GPU-vs-CPU check, with their reasons (the conformance suite's per-kernel bounds
// are tighter; these flag a broken device, not rounding): positions 0.05 mm (float rounding of a
// few-metre skinning is ~1e-4 mm), normals and tangents 0.5 degrees (a near-degenerate triangle can
// tip a gathered sum), normal maps 2 snorm16 steps (Vulkan allows 1 either way on float -> snorm).
inline constexpr double kPositionToleranceMm = 0.05, kFrameToleranceDeg = 0.5;
inline constexpr int kMapToleranceSteps = 2;

struct ReplayResult {
  ReplayPlan plan;
  std::string device;
  std::vector<FrameRecord> frames;
  std::vector<PoseIssue> issues;  // the first kMaxIssues
  size_t issueCount = 0;
  std::vector<std::string> failures;  // checks beyond tolerance, in words
  bool truthAvailable = false;  // some ground truth is in the result: per-frame truth or a model's held-out figures
  std::string truthNote;
  // Per-frame ground truth (ReplayOptions::truth).
  uint32_t truthEvery = 0;
  uint32_t truthFrames = 0;                     // frames with truth simulations
  double truthWallSeconds = 0;                  // wall time of the truth simulations (all threads together)
  std::vector<TruthSummary> truthPerCharacter;  // per scene character (empty when no truth ran)
  TruthSummary truthOverall;
  // Penetration (ReplayOptions::penetrationEvery).
  uint32_t penetrationEvery = 0;
  std::string penetrationNote;  // which body, or why none
  bool pushOut = false;         // the push-out ran (some model has body anchors and it was on)
  std::vector<PenetrationSummary> penetrationPerCharacter;  // per scene character (empty when none measured)
  PenetrationSummary penetrationOverall;
  double penetrationSeconds = 0;  // wall time of the measurements
  bool noveltyGuard = true;       // the guards were applied (ReplayOptions::noveltyGuard)
  // Quality levels.
  std::vector<ModelLevels> levels;        // per batch, plan order
  std::vector<uint32_t> levelCharacters;  // scene character of each FrameRecord::levels entry
  std::vector<std::string> levelReasons;  // the first frame's reason per entry
  std::optional<double> frameBudgetMs;    // the budget the planner spent (nullopt: none)
  std::optional<double> tolerancePixels;
  uint32_t levelHoldFrames = 0;
  std::string levelCostsSource;  // where the planner's costs came from, or why there were none
  bool failed() const { return !failures.empty() || issueCount > 0; }
};

inline constexpr size_t kMaxIssues = 2000;

class ReplayEngine {
 public:
  // Plans, loads motions (Error naming the scene and character), creates or adopts the device and
  // uploads the models of the batches.
  ReplayEngine(const runtime::Scene& scene, ModelLibrary& models, const ReplayOptions& options = {});
  ~ReplayEngine();
  ReplayEngine(const ReplayEngine&) = delete;
  ReplayEngine& operator=(const ReplayEngine&) = delete;

  const ReplayPlan& plan() const;
  // Runs every frame of the scene.
  ReplayResult run();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace swish::replay
