#pragma once
// The per-frame CPU side of the runtime for N characters of one model (paper section 2.3, steps 1, 2
// and 4): local joint rotations -> Theta -> MLP -> mesh weights + normal code -> nearest database map ->
// temporal filter; beside the MLP, the novelty guard (novelty_guard.hpp) measures each character's
// novelty and, when on, clamps and blends its mesh weights. What comes out is plain arrays for the GPU passes (no
// Vulkan here): mesh weights for the deform pass, and per character the map to blend in and its blend factor for the
// normal-map pass.
//
// Data problems never stop the frame and are never silent: each frame's output lists the joints whose
// quaternions were renormalised or replaced (with the character), the characters whose normal code was
// not finite (they keep their previous map, map 0 on a first frame), and those whose dt was negative or
// NaN (treated as 0). Wrong sizes (a programming error of the caller) throw Error.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "swish/core/skeleton.hpp"
#include "swish/model/model.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/nearest_code.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/temporal_filter.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::runtime {

struct FrameTimings {  // seconds of wall clock spent in each stage of the last evaluate()
  double theta = 0, mlp = 0, novelty = 0, lookup = 0, filter = 0, total = 0;
};

struct CharacterJointIssue {
  uint32_t character = 0;
  ThetaJointIssue joint;
};

struct FrameOutput {
  uint32_t characters = 0, meshComponents = 0, codeDims = 0;
  // characters x K, character c's weights at [c*K, c*K + K): the deform pass's K x N column-major array.
  std::vector<float> meshWeights;
  std::vector<float> normalCodes;  // characters x C, same layout
  // per character: the map to blend in (kNoMap without a database, or at a level without normal maps)
  std::vector<uint32_t> mapIndex;
  std::vector<float> blendAlpha;  // per character: its blend factor (1 on a first frame; 0 without a database)
  std::vector<BlendStep> blend;   // per character: the full filter step (empty without a database)
  // Per character: the novelty guard's measure (NaN for a model without a guard) and the blend towards
  // the mean shape it applied (0 with the guard off); the characters above the model's flag threshold.
  std::vector<float> novelty, guardBlend;
  std::vector<uint32_t> novel;
  // This frame's data problems.
  std::vector<CharacterJointIssue> jointIssues;
  std::vector<uint32_t> nonFiniteCode;  // characters whose code was NaN/Inf (kept their previous map)
  std::vector<uint32_t> invalidDt;      // characters whose dt was negative or NaN
  FrameTimings timings;
};

struct FrameEvaluatorOptions {
  CpuKernel kernel = CpuKernel::Auto;
  bool normalMaps = true;  // false: no lookup or filter even when the model has maps (mapIndex kNoMap)
  bool guard = true;       // apply the model's novelty guard to the mesh weights (measured either way)
};

class FrameEvaluator {
 public:
  // Validates the model (Model::validate) and builds the MLP, the search and one filter per character.
  FrameEvaluator(const Model& model, uint32_t characters, CpuKernel kernel = CpuKernel::Auto);
  FrameEvaluator(const Model& model, uint32_t characters, const FrameEvaluatorOptions& options);

  uint32_t characters() const { return characters_; }
  uint32_t jointsPerCharacter() const { return joints_; }
  bool hasNormalMaps() const { return search_.has_value(); }
  bool hasNoveltyGuard() const { return guard_.active(); }
  // The guard's effect on the mesh weights from the next frame on (novelty is measured either way).
  void setGuard(bool on) { guardOn_ = on; }
  bool guardOn() const { return guardOn_ && guard_.active(); }
  const MlpEvaluator& mlp() const { return mlp_; }

  // rotations: characters() x jointsPerCharacter() local rotations (Pose::local of each character, one
  // after the other). dtSeconds: one per character, or a single value for all.
  const FrameOutput& evaluate(std::span<const Quatf> rotations, std::span<const float> dtSeconds);
  const FrameOutput& evaluate(std::span<const Quatf> rotations, float dtSeconds);
  // The same from one Pose per character.
  const FrameOutput& evaluate(std::span<const Pose> poses, float dtSeconds);

  // The character's next frame starts without history (alpha 1): after a teleport or a respawn.
  void resetCharacter(uint32_t character);
  // The character's quality level (quality_levels.hpp) from the next evaluate() on; every character
  // starts at full quality. Its mesh weights beyond level.meshComponents come out as 0; without normal
  // maps it gets no lookup and no filter step (mapIndex kNoMap, blendAlpha 0), and its filter starts
  // again without history when maps return; a level that needs no network (the mean shape skinned)
  // leaves the character out of the network's batch (weights and code 0; novelty is still measured).
  // Throws Error for a character out of range or more components than the model has.
  void setLevel(uint32_t character, const QualityLevel& level);
  uint32_t levelComponents(uint32_t character) const { return levels_.at(character).components; }
  bool levelNormalMaps(uint32_t character) const { return levels_.at(character).normalMaps; }
  const FrameOutput& output() const { return out_; }

 private:
  void beginFrame();
  void thetaOf(uint32_t character, std::span<const Quatf> localRotations);
  const FrameOutput& finishFrame(std::span<const float> dtSeconds, double thetaStart);

  std::vector<uint32_t> inputJoints_;
  bool rootGravity_ = false;  // Model::rootGravity
  uint32_t characters_ = 0, joints_ = 0;
  MlpEvaluator mlp_;
  NoveltyGuardEvaluator guard_;
  bool guardOn_ = true;
  std::optional<NearestCodeSearch> search_;
  std::vector<TemporalFilter> filters_;
  std::vector<float> theta_;  // characters x thetaSize
  struct LevelUse {
    uint32_t components = 0;
    bool normalMaps = true;
  };
  std::vector<LevelUse> levels_;                         // per character
  std::vector<uint32_t> networkRows_;                    // characters the network runs for this frame
  std::vector<float> thetaNet_, weightsNet_, codesNet_;  // their compacted rows
  std::vector<ThetaJointIssue> issueScratch_;
  FrameOutput out_;
};

}  // namespace swish::runtime
