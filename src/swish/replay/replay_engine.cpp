#include "swish/replay/replay_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/report/penetration.hpp"
#include "swish/core/error.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/replay/gpu_check.hpp"
#include "swish/replay/pose_stream.hpp"
#include "swish/runtime/frame_evaluator.hpp"

namespace swish::replay {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
double addMs(double a, double b) { return std::isnan(b) ? a : (std::isnan(a) ? b : a + b); }

}  // namespace

double FrameRecord::maxPositionErrorMm() const {
  double m = 0;
  for (const auto& c : checks) m = std::max(m, c.maxPositionErrorMm);
  return m;
}
double FrameRecord::maxNormalErrorDeg() const {
  double m = 0;
  for (const auto& c : checks) m = std::max({m, c.maxNormalErrorDeg, c.maxTangentErrorDeg});
  return m;
}
int FrameRecord::maxMapErrorSteps() const {
  int m = 0;
  for (const auto& c : checks) m = std::max(m, c.maxMapErrorSteps);
  return m;
}

// One model's batch: its CPU evaluators, per-character motion and filter state, and its GPU side.
struct Batch {
  const PlannedBatch* planned = nullptr;
  const Model* model = nullptr;
  std::optional<Model> withoutMaps;  // a copy without the database, only when the plan leaves maps out
  const Model& uploaded() const { return withoutMaps ? *withoutMaps : *model; }  // the model on the GPU
  // Theta -> MLP -> novelty guard -> nearest map -> temporal filter: the one CPU frame path the API
  // uses too (runtime/frame_evaluator.hpp).
  std::optional<runtime::FrameEvaluator> frames;
  std::vector<CharacterMotion> motions;
  std::unique_ptr<gpu::GpuModel> gpuModel;
  std::unique_ptr<gpu::FrameRecorder> recorder;
  std::unique_ptr<ModelTruth> truth;  // when ground truth was asked for
  // Penetration: the bake's body, one collider per character (posed concurrently).
  std::unique_ptr<Character> bodyCharacter;
  std::string bodyNote;
  std::vector<bake::BodyCollider> colliders;
  // Quality levels: the model's ladder, each instance's level this frame, and a one-character evaluator
  // at full quality that gives truth frames the network's whole output (every level is measured from it).
  runtime::QualityLadder ladder;
  std::vector<uint32_t> levelOf;
  std::optional<runtime::FrameEvaluator> probe;
  // Per frame scratch.
  std::vector<Pose> poses;
  runtime::FrameKernelInputs inputs;
};

// Instance i of the batch at every level of its ladder (the CPU reference), from the network's whole
// output for its pose: what each level would have shown on this frame.
static std::vector<Points3f> levelPositions(Batch& B, uint32_t i) {
  const runtime::FrameOutput& o = B.probe->evaluate(std::span<const Pose>(&B.poses[i], 1), 0.f);
  const size_t jc = B.model->skeleton.size(), k = size_t(B.model->meshComponents());
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.pushOut = B.inputs.pushOut;
  in.skinMatrices.assign(B.inputs.skinMatrices.begin() + i * jc, B.inputs.skinMatrices.begin() + (i + 1) * jc);
  in.meshWeights.assign(o.meshWeights.begin(), o.meshWeights.begin() + k);
  std::vector<Points3f> out;
  for (const runtime::QualityLevel& l : B.ladder.levels) {
    in.meshComponents = {l.meshComponents};  // the reference reads the first k weights only
    out.push_back(runtime::referencePositions(B.uploaded(), in, 0, in.pushOut));
  }
  return out;
}

// One character's truth simulation, waiting for a batch of them to run in parallel.
struct TruthJob {
  size_t frame = 0;  // index into ReplayResult::frames
  size_t slot = 0;   // index into that frame's truth
  uint32_t character = 0;
  const ModelTruth* truth = nullptr;
  Pose pose;
  Points3f positions;
  std::optional<Points3f>
      withoutPushOut;  // the CPU reference's positions without the push-out (models with body anchors)
  std::optional<runtime::BlendedNormalMap> normalMap;
  size_t batch = 0;
  std::vector<Points3f> levelPositions;  // per level of the batch's ladder: the CPU reference's positions
};

struct ReplayEngine::Impl {
  const runtime::Scene& scene;
  ModelLibrary& models;
  ReplayOptions options;
  ReplayPlan plan;
  std::optional<gpu::Context> ownContext;
  gpu::Context* ctx = nullptr;
  std::vector<Batch> batches;
  // Ground truth.
  std::vector<TruthJob> truthJobs;
  std::vector<TruthPool> truthPools;  // per scene character
  TruthPool truthOverall;
  uint32_t truthDone = 0, truthTotal = 0;
  // Quality levels: the planner over every on-screen character, in plan order (batch, instance).
  std::optional<runtime::LevelPlanner> levelPlanner;
  std::vector<std::pair<size_t, uint32_t>> levelSlots;
  std::vector<Eigen::Vector3d> levelRoots;                     // per frame scratch: each slot's root in the world
  std::vector<std::vector<std::vector<double>>> levelTruthMm;  // [batch][level]: every vertex distance
  std::string levelCostsSource;
  std::vector<std::string> firstReasons;
  bool costScaleSet = false;
  std::vector<double> costRatios;  // the last kCostWindow frames' measured over predicted GPU time
  static constexpr size_t kCostWindow = 15;
  // Penetration.
  std::vector<PenetrationSummary> penetrationPools;  // per scene character
  PenetrationSummary penetrationOverall;
  double penetrationSeconds = 0;

  Impl(const runtime::Scene& s, ModelLibrary& m, const ReplayOptions& o) : scene(s), models(m), options(o) {}
  void setUp();
  void setUpLevels();
  void calibrateLevels();
  void calibrationFrame(Batch& B, const std::vector<Pose>& poses, uint32_t level);
  void applyLevels(uint64_t frame, FrameRecord& rec);
  bool truthFrame(uint32_t index) const;
  FrameRecord runFrame(uint32_t index, ReplayResult& result);
  void measurePenetration(FrameRecord& rec);
  void runTruth(ReplayResult& result);
};

void ReplayEngine::Impl::setUp() {
  const std::string where = scene.source.empty() ? std::string("scene") : scene.source.string();
  plan = planReplay(scene, models.modelMap());
  batches.resize(plan.batches.size());
  for (size_t b = 0; b < plan.batches.size(); ++b) {
    Batch& B = batches[b];
    B.planned = &plan.batches[b];
    B.model = &models.at(B.planned->model).model;
    runtime::FrameEvaluatorOptions eo;
    eo.normalMaps = B.planned->normalMaps;
    eo.guard = options.noveltyGuard;
    B.frames.emplace(*B.model, uint32_t(B.planned->characters.size()), eo);
    for (uint32_t c : B.planned->characters) {
      const runtime::SceneCharacter& ch = scene.characters[c];
      try {
        if (ch.clip) {
          const bool inFile = !ch.clip->jointMapFile.empty();
          auto clip =
              models.clip(ch.clip->file, ch.model, ch.clip->jointMap, inFile ? ch.clip->jointMapFile.string() : where,
                          inFile ? "" : "characters[" + std::to_string(c) + "].animation.jointMap");
          if (!ch.clip->clipName.empty() && ch.clip->clipName != clip->name)
            throw Error("the file's clip is '" + clip->name + "', not '" + ch.clip->clipName + "'");
          B.motions.emplace_back(clip, *ch.clip, B.model->skeleton, ch.name);
        } else {
          B.motions.emplace_back(std::make_shared<PoseStream>(readPoseStream(*ch.poseStream)), B.model->skeleton,
                                 ch.name);
        }
      } catch (const Error& e) {
        throw Error(where + ": characters[" + std::to_string(c) + "] ('" + ch.name + "'): " + e.what());
      }
    }
    if (options.penetrationEvery > 0 && !B.planned->characters.empty()) {
      B.bodyCharacter = rebuildBakeCharacter(models.at(B.planned->model), B.bodyNote);
      if (B.bodyCharacter && B.bodyCharacter->body.triangleCount() == 0) {
        B.bodyNote = "the bake's character '" + B.bodyCharacter->name + "' has no body mesh";
        B.bodyCharacter.reset();
      }
      if (B.bodyCharacter) {
        const bake::BodyCollider prototype(B.bodyCharacter->body, bake::kPenetrationCellSize,
                                           "model '" + B.planned->model + "' body");
        B.colliders.assign(B.planned->characters.size(), prototype);
      }
    }
  }
  setUpLevels();
  if (!plan.gpuWork) return;
  if (options.context) {
    ctx = options.context;
  } else {
    ownContext.emplace(gpu::Context::create(options.device));
    ctx = &*ownContext;
  }
  for (Batch& B : batches) {
    if (!B.planned->normalMaps) {  // not uploaded: the plan leaves normal maps out
      B.withoutMaps.emplace(*B.model);
      B.withoutMaps->normalMaps = NormalMapDatabase{};
    }
    B.gpuModel = std::make_unique<gpu::GpuModel>(*ctx, B.uploaded(), B.planned->model);
    gpu::FrameRecorderOptions ro;
    ro.framesInFlight = 1;
    ro.tangentFrames = B.planned->tangentFrames;
    ro.normalMaps = B.planned->normalMaps;
    B.recorder = std::make_unique<gpu::FrameRecorder>(*ctx, *B.gpuModel, uint32_t(B.planned->characters.size()), ro);
    // Ground truth needs the run time's outputs, hence GPU work.
    if (options.truth.every > 0) B.truth = std::make_unique<ModelTruth>(models.at(B.planned->model), options.truth);
  }
  // The memory the device really takes: where it lays the normal-map images over the blend's output
  // (the same for every recorder on one device), no separate blended-maps buffer.
  const auto withMaps =
      std::find_if(batches.begin(), batches.end(), [](const Batch& B) { return B.planned->normalMaps; });
  if (withMaps != batches.end() && withMaps->recorder->frame(0).normalMaps.sharesTexels()) {
    PlannerOptions po;
    po.normalMapsShareTexels = true;
    plan.allocations = planReplay(scene, models.modelMap(), po).allocations;
  }
}

void ReplayEngine::Impl::setUpLevels() {
  const std::string where = scene.source.empty() ? std::string("scene") : scene.source.string();
  std::vector<const runtime::QualityLadder*> ladders;
  std::vector<std::optional<uint32_t>> fixed;
  for (size_t b = 0; b < batches.size(); ++b) {
    Batch& B = batches[b];
    B.ladder = runtime::ladderOf(*B.model, B.planned->normalMaps);
    B.levelOf.assign(B.planned->characters.size(), 0);
    if (options.truth.every > 0) {
      runtime::FrameEvaluatorOptions eo;
      eo.normalMaps = false;
      eo.guard = options.noveltyGuard;
      B.probe.emplace(*B.model, 1u, eo);
    }
    for (uint32_t i = 0; i < B.planned->characters.size(); ++i) {
      const runtime::SceneCharacter& ch = scene.characters[B.planned->characters[i]];
      const std::string& name = options.fixedLevel.empty() ? ch.level : options.fixedLevel;
      fixed.push_back(name.empty() ? std::nullopt
                                   : std::optional<uint32_t>(runtime::levelIndex(
                                         B.ladder, name,
                                         where + ": characters[" + std::to_string(B.planned->characters[i]) + "] ('" +
                                             ch.name + "') level")));
      levelSlots.emplace_back(b, i);
    }
  }
  for (Batch& B : batches)
    for (size_t i = 0; i < B.planned->characters.size(); ++i) ladders.push_back(&B.ladder);
  const runtime::LevelPlannerSettings ls = scene.levelPlannerSettings(options.frameBudgetMs, options.tolerancePixels);
  levelPlanner.emplace(std::move(ladders), std::move(fixed), ls);
  levelTruthMm.resize(batches.size());
  for (size_t b = 0; b < batches.size(); ++b) levelTruthMm[b].resize(batches[b].ladder.size());
  levelCostsSource = ls.frameBudgetMs ? "not calibrated" : "no frame budget: the costs were not needed";
}

// The planner's costs: per batch and level, the GPU time of a frame with every character of the batch at
// that level (median of a few frames of the scene's first poses) shared out per character, so that a
// frame's fixed cost is shared too. The calibration's frames are thrown away: filters start again (the
// first real frame blends with alpha 1) and decoded maps are forgotten.
// The CPU frame's output as the GPU passes' inputs: mesh weights, each instance's components (its
// level), and with maps the selected map and blend factor of each character (kNoMap without).
static void setKernelInputs(Batch& B, const runtime::FrameOutput& o) {
  const uint32_t n = uint32_t(B.planned->characters.size());
  B.inputs.meshWeights = o.meshWeights;
  B.inputs.meshComponents.resize(n);
  for (uint32_t i = 0; i < n; ++i) B.inputs.meshComponents[i] = B.ladder[B.levelOf[i]].meshComponents;
  B.inputs.selectedMaps.clear();
  B.inputs.blendAlpha.clear();
  if (B.frames->hasNormalMaps())
    for (uint32_t i = 0; i < n; ++i) {
      B.inputs.selectedMaps.push_back(o.blend[i].selectedMap);
      B.inputs.blendAlpha.push_back(o.blend[i].alpha);
    }
}

// One frame of the batch with every character at `level`, submitted and waited on (calibration only).
void ReplayEngine::Impl::calibrationFrame(Batch& B, const std::vector<Pose>& poses, uint32_t level) {
  const uint32_t n = uint32_t(B.planned->characters.size());
  for (uint32_t i = 0; i < n; ++i) {
    B.frames->resetCharacter(i);
    B.frames->setLevel(i, B.ladder[level]);
  }
  B.levelOf.assign(n, level);
  setKernelInputs(B, B.frames->evaluate(std::span<const Pose>(poses), 0.f));
  VkCommandBuffer cmd = ctx->beginOneTime();
  try {
    B.recorder->record(cmd, 0, B.inputs);
  } catch (...) {
    ctx->abandonOneTime(cmd);
    throw;
  }
  ctx->endOneTimeAndWait(cmd);
}

void ReplayEngine::Impl::calibrateLevels() {
  if (!plan.gpuWork || !levelPlanner || !levelPlanner->settings().frameBudgetMs) return;
  constexpr int kRepeats = 5;
  std::vector<PoseIssue> ignored;
  std::vector<std::vector<double>> perBatch(batches.size());
  for (size_t b = 0; b < batches.size(); ++b) {
    Batch& B = batches[b];
    const uint32_t n = uint32_t(B.planned->characters.size());
    const size_t jc = B.model->skeleton.size();
    std::vector<Pose> poses;
    B.inputs.instanceCount = n;
    B.inputs.pushOut = options.pushOut;
    B.inputs.skinMatrices.resize(n * jc);
    for (uint32_t i = 0; i < n; ++i) {
      poses.push_back(B.motions[i].poseAt(scene.timeOfFrame(scene.firstFrame), scene.firstFrame, ignored));
      const auto mats = B.model->skeleton.skinningMatrices(poses.back());
      std::copy(mats.begin(), mats.end(), B.inputs.skinMatrices.begin() + i * jc);
    }
    // A real GPU idles at low clocks: keep it busy at full quality for a quarter of a second (at least
    // 10 frames) before measuring, as a game's steady state would.
    const auto warmStart = Clock::now();
    for (int r = 0; r < 10 || msSince(warmStart) < 250.0; ++r) calibrationFrame(B, poses, 0);
    for (uint32_t l = 0; l < B.ladder.size(); ++l) {
      std::vector<double> ms;
      for (int r = 0; r < kRepeats + 1; ++r) {
        calibrationFrame(B, poses, l);
        // The first frame decodes its maps and warms caches up; the others are the steady state, in
        // which a frame decodes only the maps newly selected.
        if (r > 0) ms.push_back(B.recorder->stageTimes(0).totalMs);
      }
      std::sort(ms.begin(), ms.end());
      perBatch[b].push_back(ms[ms.size() / 2] / double(std::max(n, 1u)));
    }
    for (uint32_t i = 0; i < n; ++i) {
      B.frames->resetCharacter(i);
      B.frames->setLevel(i, B.ladder[0]);
    }
    B.levelOf.assign(n, 0);
    B.recorder->forgetDecodedMaps();
  }
  runtime::LevelCosts costs;
  for (const auto& [b, i] : levelSlots) costs.msPerCharacter.push_back(perBatch[b]);
  for (double v : costs.msPerCharacter.empty() ? std::vector<double>{} : costs.msPerCharacter[0])
    if (!std::isfinite(v)) {
      levelCostsSource = "not calibrated: the device has no timestamps";
      return;
    }
  costs.source = "calibrated on " + ctx->deviceName() + ": the median of " + std::to_string(kRepeats) +
                 " frames per level with every character at that level";
  levelCostsSource = costs.source;
  levelPlanner->setCosts(std::move(costs));
}

// Plans this frame's levels from each on-screen character's root in the world and hands them to the
// evaluators and the GPU inputs.
void ReplayEngine::Impl::applyLevels(uint64_t frame, FrameRecord& rec) {
  levelRoots.clear();
  for (const auto& [b, i] : levelSlots) {
    const runtime::SceneCharacter& ch = scene.characters[batches[b].planned->characters[i]];
    levelRoots.push_back(ch.placement.apply(batches[b].poses[i].rootTranslation));
  }
  const runtime::PlannedLevels& planned = levelPlanner->plan(frame, levelRoots);
  for (size_t s = 0; s < levelSlots.size(); ++s) {
    const auto& [b, i] = levelSlots[s];
    Batch& B = batches[b];
    const uint32_t level = planned.characters[s].level;
    if (level != B.levelOf[i] || frame == scene.firstFrame) B.frames->setLevel(i, B.ladder[level]);
    B.levelOf[i] = level;
    rec.levels.push_back(uint8_t(level));
    rec.levelChanges += planned.characters[s].changed ? 1u : 0u;
  }
  if (firstReasons.empty())
    for (const runtime::LevelChoice& c : planned.characters) firstReasons.push_back(c.reason);
  rec.predictedGpuMs = planned.predictedMs;
  rec.weightedErrorMm = planned.weightedErrorMm;
  rec.fullErrorMm = planned.fullErrorMm;
}

bool ReplayEngine::Impl::truthFrame(uint32_t index) const {
  if (options.truth.every == 0 || index % options.truth.every != 0) return false;
  for (const Batch& B : batches)
    if (B.truth && B.truth->available()) return true;
  return false;
}

FrameRecord ReplayEngine::Impl::runFrame(uint32_t index, ReplayResult& result) {
  FrameRecord rec;
  rec.frame = scene.firstFrame + index;
  const double seconds = scene.timeOfFrame(rec.frame);
  const float dt = index == 0 ? 0.f : float(1.0 / scene.framesPerSecond);
  FrameTimes& t = rec.times;
  t.gpuDeform = t.gpuTangents = t.gpuDecode = t.gpuBlend = t.gpuTotal = kNaN;
  std::vector<PoseIssue> issues;

  for (Batch& B : batches) {
    const Model& m = *B.model;
    const uint32_t n = uint32_t(B.planned->characters.size());
    const size_t jc = m.skeleton.size();
    auto t0 = Clock::now();
    std::vector<Pose>& poses = B.poses;
    poses.clear();
    poses.reserve(n);
    B.inputs.instanceCount = n;
    B.inputs.pushOut = options.pushOut;
    B.inputs.skinMatrices.resize(n * jc);
    for (uint32_t i = 0; i < n; ++i) {
      poses.push_back(B.motions[i].poseAt(seconds, rec.frame, issues));
      // Character space: the placement never enters the skinning (precision far from the origin).
      const auto mats = m.skeleton.skinningMatrices(poses.back());
      std::copy(mats.begin(), mats.end(), B.inputs.skinMatrices.begin() + i * jc);
    }
    t.pose += msSince(t0);
  }
  {
    auto t0 = Clock::now();
    applyLevels(rec.frame, rec);
    t.pose += msSince(t0);
  }

  for (Batch& B : batches) {
    const Model& m = *B.model;
    const uint32_t n = uint32_t(B.planned->characters.size());
    std::vector<Pose>& poses = B.poses;
    const runtime::FrameOutput& o = B.frames->evaluate(std::span<const Pose>(poses), dt);
    t.theta += 1000.0 * o.timings.theta;
    t.mlp += 1000.0 * o.timings.mlp;
    t.novelty += 1000.0 * o.timings.novelty;
    t.lookup += 1000.0 * (o.timings.lookup + o.timings.filter);
    for (uint32_t c : o.nonFiniteCode)
      issues.push_back({rec.frame, scene.characters[B.planned->characters[c]].name, "", "non-finite normal code",
                        "previous normal map kept"});
    if (B.frames->hasNoveltyGuard())
      for (uint32_t i = 0; i < n; ++i)
        rec.novelty.push_back(
            {B.planned->characters[i], o.novelty[i], o.guardBlend[i], !(o.novelty[i] <= m.noveltyGuard.flagAbove)});
    setKernelInputs(B, o);
  }

  const bool check = plan.gpuWork && index % scene.outputs.gpuCheckEvery == 0;
  rec.truthFrame = truthFrame(index);
  const bool readBack = plan.gpuWork && (check || rec.truthFrame || options.onCharacterOutput);
  if (plan.gpuWork) {
    // The reference needs each character's normal map as the GPU had it before this frame.
    std::vector<std::vector<runtime::BlendedNormalMap>> prevMaps(batches.size());
    if (check)
      for (size_t b = 0; b < batches.size(); ++b) {
        Batch& B = batches[b];
        if (!B.planned->normalMaps) continue;
        const auto& imgs = B.recorder->frame(0).normalMaps;
        const auto all = imgs.download(*ctx);
        const size_t per = size_t(imgs.width()) * imgs.height() * 2;
        for (uint32_t i = 0; i < B.planned->characters.size(); ++i)
          prevMaps[b].push_back(
              {imgs.width(), imgs.height(), std::vector<int16_t>(all.begin() + i * per, all.begin() + (i + 1) * per)});
      }
    auto t0 = Clock::now();
    VkCommandBuffer cmd = ctx->beginOneTime();
    try {
      for (Batch& B : batches) rec.gpuDispatches += B.recorder->record(cmd, index, B.inputs);
    } catch (...) {
      ctx->abandonOneTime(cmd);
      throw;
    }
    t.record = msSince(t0);
    t0 = Clock::now();
    ctx->endOneTimeAndWait(cmd);
    t.gpuWait = msSince(t0);
    for (Batch& B : batches) {
      const gpu::StageTimes s = B.recorder->stageTimes(0);
      t.gpuDeform = addMs(t.gpuDeform, s.deformMs);
      t.gpuTangents = addMs(t.gpuTangents, s.tangentFramesMs);
      t.gpuDecode = addMs(t.gpuDecode, s.vqDecodeMs);
      t.gpuBlend = addMs(t.gpuBlend, s.normalBlendMs);
      t.gpuTotal = addMs(t.gpuTotal, s.totalMs);
    }
    // The planner's costs follow the GPU as it runs (clocks, load): the median of the last frames'
    // measured time over their unscaled prediction (a median, so that one slow frame moves nothing; the
    // first frame, which decodes every map it selects, is left out).
    const double unscaled = levelPlanner ? levelPlanner->last().unscaledMs : kNaN;
    if (index > 0 && std::isfinite(unscaled) && unscaled > 0 && std::isfinite(t.gpuTotal) && t.gpuTotal > 0) {
      costRatios.push_back(t.gpuTotal / unscaled);
      if (costRatios.size() > kCostWindow) costRatios.erase(costRatios.begin());
      if (costRatios.size() >= 3) {
        std::vector<double> sorted = costRatios;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        levelPlanner->setCostScale(sorted[sorted.size() / 2]);
        costScaleSet = true;
      }
    }
    rec.costScale = levelPlanner && costScaleSet ? levelPlanner->costScale() : kNaN;
    if (readBack) {
      rec.checked = check;
      for (size_t b = 0; b < batches.size(); ++b) {
        Batch& B = batches[b];
        const runtime::ReferenceFrameOutputs gpuOut = B.recorder->download(0);
        if (check) {
          const runtime::ReferenceFrameOutputs cpuOut = runtime::referenceFrame(B.uploaded(), B.inputs, prevMaps[b]);
          for (uint32_t i = 0; i < B.planned->characters.size(); ++i) {
            CharacterCheck c = compareInstance(gpuOut, cpuOut, i, B.planned->characters[i]);
            if (!c.ok)
              result.failures.push_back(
                  "frame " + std::to_string(rec.frame) + ", character '" + scene.characters[c.character].name +
                  "': GPU output differs from the CPU reference (" + std::to_string(c.maxPositionErrorMm) + " mm, " +
                  std::to_string(c.maxNormalErrorDeg) + " deg, " + std::to_string(c.maxMapErrorSteps) + " map steps)");
            rec.checks.push_back(c);
          }
        }
        if (rec.truthFrame && B.truth && B.truth->available())
          for (uint32_t i = 0; i < B.planned->characters.size(); ++i) {
            TruthJob job;
            job.frame = result.frames.size();  // the index this record gets
            job.slot = rec.truth.size();
            job.character = B.planned->characters[i];
            job.truth = B.truth.get();
            job.pose = B.poses[i];
            job.positions = gpuOut.positions[i];
            if (B.inputs.pushOut && !B.uploaded().bodyAnchors.empty())
              job.withoutPushOut = runtime::referencePositions(B.uploaded(), B.inputs, i, false);
            if (B.truth->normalMaps() && i < gpuOut.normalMaps.size() && B.inputs.selectedMaps.size() > i &&
                B.inputs.selectedMaps[i] != runtime::kNoMap)
              job.normalMap = gpuOut.normalMaps[i];
            job.batch = b;
            job.levelPositions = levelPositions(B, i);
            rec.truth.push_back({});
            rec.truth.back().character = job.character;
            rec.truth.back().failure = "not simulated yet";
            truthJobs.push_back(std::move(job));
          }
        if (options.onCharacterOutput)
          for (uint32_t i = 0; i < B.planned->characters.size(); ++i)
            options.onCharacterOutput(rec.frame, B.planned->characters[i], gpuOut, i);
      }
    }
  }
  if (options.penetrationEvery > 0 && index % options.penetrationEvery == 0) measurePenetration(rec);
  rec.poseIssues = uint32_t(issues.size());
  result.issueCount += issues.size();
  for (auto& i : issues)
    if (result.issues.size() < kMaxIssues) result.issues.push_back(std::move(i));
  return rec;
}

// The CPU reference's positions of each character with a body, before and after the push-out, against
// that character's posed body; characters in parallel (each has its own collider).
void ReplayEngine::Impl::measurePenetration(FrameRecord& rec) {
  const auto t0 = Clock::now();
  for (Batch& B : batches) {
    if (B.colliders.empty()) continue;
    const Model& m = B.uploaded();
    const uint32_t n = uint32_t(B.planned->characters.size()), jc = uint32_t(m.skeleton.size());
    const bool pushed = B.inputs.pushOut && !m.bodyAnchors.empty();
    std::vector<CharacterPenetration> out(n);
    tbb::parallel_for(uint32_t(0), n, [&](uint32_t i) {
      bake::BodyCollider& c = B.colliders[i];
      c.pose(std::vector<Mat4f>(B.inputs.skinMatrices.begin() + size_t(i) * jc,
                                B.inputs.skinMatrices.begin() + size_t(i + 1) * jc));
      out[i].character = B.planned->characters[i];
      out[i].model = bake::measurePenetration(c, runtime::referencePositions(m, B.inputs, i, false));
      if (pushed) {
        out[i].pushedMeasured = true;
        out[i].pushed = bake::measurePenetration(c, runtime::referencePositions(m, B.inputs, i, true));
      }
    });
    for (const CharacterPenetration& p : out) {
      for (PenetrationSummary* s : {&penetrationPools[p.character], &penetrationOverall}) {
        s->model.add(p.model);
        if (p.pushedMeasured) s->pushed.add(p.pushed), s->pushedMeasured = true;
      }
      rec.penetration.push_back(p);
    }
  }
  penetrationSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
}

// Runs the gathered truth simulations in parallel, one task each (a pose takes about a second, so
// nothing is gained by grouping them), then stores and pools the results in job order.
void ReplayEngine::Impl::runTruth(ReplayResult& result) {
  if (truthJobs.empty()) return;
  const auto t0 = Clock::now();
  std::vector<TruthMeasurement> out(truthJobs.size());
  std::mutex mutex;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, truthJobs.size(), 1),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t k = range.begin(); k != range.end(); ++k) {
          const TruthJob& j = truthJobs[k];
          // Isolated: while the transfer's inner parallel loops wait, this thread must not pick up
          // another pose, whose second of simulation would then count in this pose's time.
          tbb::this_task_arena::isolate([&] {
            out[k] = j.truth->measure(j.pose, j.positions, j.normalMap ? &*j.normalMap : nullptr,
                                      j.withoutPushOut ? &*j.withoutPushOut : nullptr);
          });
          std::lock_guard<std::mutex> lock(mutex);
          ++truthDone;
          if (options.truthProgress) options.truthProgress(truthDone, truthTotal);
        }
      },
      tbb::simple_partitioner());
  result.truthWallSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
  for (size_t k = 0; k < truthJobs.size(); ++k) {
    const TruthJob& j = truthJobs[k];
    out[k].summary.character = j.character;
    if (out[k].summary.ok)
      for (size_t l = 0; l < j.levelPositions.size(); ++l)
        for (Eigen::Index v = 0; v < j.levelPositions[l].rows(); ++v)
          levelTruthMm[j.batch][l].push_back(
              1000.0 * double((j.levelPositions[l].row(v) - out[k].truthPositions.row(v)).norm()));
    result.frames[j.frame].truth[j.slot] = out[k].summary;
    truthPools[j.character].add(out[k]);
    truthOverall.add(out[k]);
  }
  truthJobs.clear();
}

ReplayEngine::ReplayEngine(const runtime::Scene& scene, ModelLibrary& models, const ReplayOptions& options)
    : impl_(std::make_unique<Impl>(scene, models, options)) {
  impl_->setUp();
}

ReplayEngine::~ReplayEngine() = default;

const ReplayPlan& ReplayEngine::plan() const { return impl_->plan; }

ReplayResult ReplayEngine::run() {
  Impl& I = *impl_;
  ReplayResult r;
  r.plan = I.plan;
  r.device = I.ctx ? I.ctx->deviceName() : std::string("(no GPU work planned)");
  const uint32_t every = I.options.truth.every;
  r.truthEvery = every;
  if (every == 0) {
    r.truthNote =
        "no per-frame ground truth requested (--truth-every N); a baked model's held-out-pose errors (its "
        "metadata) are quoted under Models";
  } else if (!I.plan.gpuWork || I.batches.empty()) {
    r.truthNote = "--truth-every " + std::to_string(every) +
                  ": no ground truth: no GPU work is planned (no character on "
                  "screen, or outputs that need no meshes), so there is no run-time output to measure";
  } else {
    // Per model: what its truth simulates, or why it has none.
    uint32_t characters = 0;
    for (const Batch& B : I.batches) {
      if (!r.truthNote.empty()) r.truthNote += "; ";
      const bool ok = B.truth && B.truth->available();
      r.truthNote += "model '" + B.planned->model + "': " +
                     (ok ? "ground truth every " + std::to_string(every) + " frames from " : "no ground truth: ") +
                     (B.truth ? B.truth->note() : std::string("not prepared"));
      if (ok) characters += uint32_t(B.planned->characters.size());
    }
    I.truthTotal = characters * ((I.scene.frameCount + every - 1) / every);
    I.truthPools = std::vector<TruthPool>(I.scene.characters.size());
  }
  r.penetrationEvery = I.options.penetrationEvery;
  r.noveltyGuard = I.options.noveltyGuard;
  for (const Batch& B : I.batches)
    if (I.options.pushOut && I.plan.gpuWork && !B.model->bodyAnchors.empty()) r.pushOut = true;
  if (I.options.penetrationEvery == 0) {
    r.penetrationNote = "not measured (--penetration-every 0)";
  } else {
    for (const Batch& B : I.batches) {
      if (!r.penetrationNote.empty()) r.penetrationNote += "; ";
      r.penetrationNote += "model '" + B.planned->model + "': " +
                           (B.bodyCharacter ? "the body of the bake's character '" + B.bodyCharacter->name + "' (" +
                                                  std::to_string(B.bodyCharacter->body.vertexCount()) + " vertices)"
                                            : "not measured: " + B.bodyNote);
    }
    I.penetrationPools = std::vector<PenetrationSummary>(I.scene.characters.size());
  }
  // Per-model ground truth: the bake's error on held-out poses, when the model's metadata has it.
  for (const auto& e : I.models.entries())
    if (e->model.metadata.find("\"held_out_poses\"") != std::string::npos) r.truthAvailable = true;
  // Truth simulations wait until a few frames' worth can run in parallel (bounded memory: a job holds
  // one character's output and normal map).
  const size_t truthBatch = size_t(std::max(16, 4 * tbb::this_task_arena::max_concurrency()));
  I.calibrateLevels();
  for (uint32_t f = 0; f < I.scene.frameCount; ++f) {
    r.frames.push_back(I.runFrame(f, r));
    if (r.frames.back().truthFrame) ++r.truthFrames;
    if (I.options.progress) I.options.progress(f + 1, I.scene.frameCount);
    if (I.truthJobs.size() >= truthBatch) I.runTruth(r);
  }
  I.runTruth(r);
  if (!I.truthPools.empty()) {
    for (const TruthPool& p : I.truthPools) r.truthPerCharacter.push_back(p.summary());
    r.truthOverall = I.truthOverall.summary();
    if (r.truthOverall.samples > 0) r.truthAvailable = true;
  }
  bool anyPenetration = false;
  for (const PenetrationSummary& p : I.penetrationPools) anyPenetration |= p.model.frames > 0;
  if (anyPenetration) {
    r.penetrationPerCharacter = I.penetrationPools;
    r.penetrationOverall = I.penetrationOverall;
  }
  r.penetrationSeconds = I.penetrationSeconds;
  // Quality levels.
  if (I.levelPlanner) {
    const runtime::LevelPlannerSettings& ls = I.levelPlanner->settings();
    r.frameBudgetMs = ls.frameBudgetMs;
    r.tolerancePixels = ls.tolerancePixels;
    r.levelHoldFrames = ls.holdFrames;
    r.levelCostsSource = I.levelCostsSource;
    r.levelReasons = I.firstReasons;
    for (const auto& [b, i] : I.levelSlots) r.levelCharacters.push_back(I.batches[b].planned->characters[i]);
    for (size_t b = 0; b < I.batches.size(); ++b) {
      ModelLevels ml;
      ml.model = I.batches[b].planned->model;
      ml.ladder = I.batches[b].ladder;
      const runtime::LevelCosts& costs = I.levelPlanner->costs();
      for (size_t s = 0; s < I.levelSlots.size() && !costs.empty(); ++s)
        if (I.levelSlots[s].first == b) {
          ml.calibratedMsPerCharacter = costs.msPerCharacter[s];
          break;
        }
      for (std::vector<double>& mm : I.levelTruthMm[b]) {
        if (mm.empty()) continue;
        LevelTruth t;
        t.samples = uint32_t(mm.size());
        double sum = 0;
        for (double v : mm) sum += v;
        t.meanMm = sum / double(mm.size());
        std::sort(mm.begin(), mm.end());
        t.p95Mm = mm[std::min(mm.size() - 1, size_t(0.95 * double(mm.size())))];
        t.maxMm = mm.back();
        ml.truth.push_back(t);
      }
      r.levels.push_back(std::move(ml));
    }
  }
  // With validation on, a validation message is a failure of the run like a wrong output.
  if (I.ctx && I.ctx->validationEnabled())
    for (const std::string& m : I.ctx->validationMessages()) r.failures.push_back("Vulkan validation: " + m);
  return r;
}

}  // namespace swish::replay
