#pragma once
// The level planner: per character per frame, which quality level (quality_levels.hpp) it runs at, and
// why. Vulkan-free; the replay calls it every frame (and `swish replay --plan` for the first frame).
//
// What it weighs:
//   - Size on screen. Each character is projected through the scene's camera (position, target, vertical
//     field of view, image height in pixels): its height in pixels at its distance, and the pixels one
//     millimetre of garment covers there. A level's error on screen is its measured vertex error (the
//     ladder's mean, mm) times that; a character's weight is its projected area, so the error a player
//     sees is the screen-weighted mean over characters.
//   - A pixel tolerance (optional): a character runs at the cheapest level whose error on screen is below
//     it, and at the cheapest level when it is out of view. Without one every character starts from full
//     quality (what the replay did before levels), in view or not.
//   - A frame budget (optional, GPU milliseconds): while the predicted frame cost is above it, the
//     character whose next cheaper level adds the least screen-weighted error per millisecond saved is
//     stepped down (greedy, as LOD systems spend a budget): small and far characters first, the nearest
//     and largest keep their quality longest. The predicted cost is the sum of per-character costs per
//     level (LevelCosts), calibrated on the device by the replay.
//   - Hysteresis: a character keeps a level for at least holdFrames after a change (so it changes at most
//     once per hold; the first frame's assignment is not a change), and stepping a character down to a
//     level it already holds costs half, so that characters of near-equal weight do not trade places
//     from frame to frame.
//   - A level the scene fixes for a character (a host with its own LOD system) is kept as it is.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish::runtime {

struct LevelCamera {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d(0, 1, 0);
  double verticalFovDegrees = 50.0;
  double imageHeightPixels = 1080.0;
};

// What a character looks like from the camera this frame.
struct CharacterView {
  double distance = 0;      // metres from the camera, along the view direction (depth)
  double heightPixels = 0;  // projected height of a characterHeight-metre figure
  double pixelsPerMm = 0;   // image pixels one millimetre covers at that depth
  bool inView = false;      // in front of the camera and within the field of view (with a margin)
  double weight() const { return inView ? heightPixels * heightPixels : 0.0; }  // projected area, px^2
};

inline constexpr double kCharacterHeightMetres = 1.8;

CharacterView viewOf(const LevelCamera& camera, const Eigen::Vector3d& characterRoot);

struct LevelPlannerSettings {
  LevelCamera camera;
  std::optional<double> frameBudgetMs;  // GPU ms per frame for all characters
  std::optional<double> tolerancePixels;
  uint32_t holdFrames = 30;  // at least this many frames between two changes of one character
};

// Per character and level: the GPU milliseconds per frame the character adds at that level.
struct LevelCosts {
  std::vector<std::vector<double>> msPerCharacter;  // [character][level]
  std::string source;                               // where the figures come from ("calibrated on ...")
  bool empty() const { return msPerCharacter.empty(); }
};

struct LevelChoice {
  uint32_t level = 0;
  bool changed = false;  // differs from the previous frame's level
  CharacterView view;
  std::string reason;
};

struct PlannedLevels {
  std::vector<LevelChoice> characters;                            // in the planner's character order
  double predictedMs = std::numeric_limits<double>::quiet_NaN();  // NaN without costs; scaled (setCostScale)
  double unscaledMs = std::numeric_limits<double>::quiet_NaN();   // the same before the scale
  bool overBudget = false;  // the budget could not be met (levels held, fixed or at their cheapest)
  // Screen-weighted mean vertex error (mm) of the chosen levels and of full quality (ladder means; NaN
  // when the ladder is not measured or no character is in view).
  double weightedErrorMm = std::numeric_limits<double>::quiet_NaN();
  double fullErrorMm = std::numeric_limits<double>::quiet_NaN();
};

class LevelPlanner {
 public:
  // ladders: one per character (the ladder of the model it wears); fixedLevels: per character, a level
  // index the scene fixes, or nullopt. Throws Error when a fixed level is outside its ladder.
  LevelPlanner(std::vector<const QualityLadder*> ladders, std::vector<std::optional<uint32_t>> fixedLevels,
               const LevelPlannerSettings& settings);

  // Costs for the budget; without them a budget is not applied (the plan says so).
  void setCosts(LevelCosts costs);
  // The GPU as it runs now against the costs: the replay feeds back each frame's measured GPU time over
  // its unscaled prediction (a real GPU's clocks and a busy machine move both), and every cost is
  // multiplied by this from the next plan on. 1 until set; must be positive and finite.
  void setCostScale(double scale);
  double costScale() const { return scale_; }
  const LevelCosts& costs() const { return costs_; }
  const LevelPlannerSettings& settings() const { return settings_; }
  size_t characters() const { return ladders_.size(); }

  // The levels of scene frame `frame` (frames in increasing order), from each character's root in world
  // space. The first call sets every level; later calls respect the hold.
  const PlannedLevels& plan(uint64_t frame, std::span<const Eigen::Vector3d> roots);
  const PlannedLevels& last() const { return out_; }

 private:
  double errorOf(size_t c, uint32_t level) const;
  double costOf(size_t c, uint32_t level) const;

  std::vector<const QualityLadder*> ladders_;
  std::vector<std::optional<uint32_t>> fixed_;
  LevelPlannerSettings settings_;
  LevelCosts costs_;
  double scale_ = 1.0;
  std::vector<uint32_t> current_;
  std::vector<std::optional<uint64_t>> lastChange_;  // none: not changed since the first plan
  bool first_ = true;
  PlannedLevels out_;
};

// A level given by name ("k64") or by index ("2") in `ladder`; Error naming `what` and the levels
// offered when there is no such level.
uint32_t levelIndex(const QualityLadder& ladder, const std::string& nameOrIndex, const std::string& what);

}  // namespace swish::runtime
