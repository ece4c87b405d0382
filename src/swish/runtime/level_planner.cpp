#include "swish/runtime/level_planner.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "swish/core/error.hpp"

namespace swish::runtime {

namespace {

std::string fixed1(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(std::abs(v) < 10 ? 2 : 1);
  s << v;
  return s.str();
}

}  // namespace

CharacterView viewOf(const LevelCamera& camera, const Eigen::Vector3d& root) {
  CharacterView v;
  Eigen::Vector3d forward = camera.target - camera.position;
  if (!(forward.norm() > 1e-9)) forward = Eigen::Vector3d(0, 0, 1);
  forward.normalize();
  // The figure's centre: the root is at the hips; the body reaches about as far up as down.
  const Eigen::Vector3d toCharacter = root - camera.position;
  v.distance = toCharacter.dot(forward);
  const double tanHalf = std::tan(camera.verticalFovDegrees * std::numbers::pi / 360.0);
  const double focalPixels = camera.imageHeightPixels / (2.0 * tanHalf);
  if (!(v.distance > 0.05)) return v;  // behind the camera or at it: not in view
  v.pixelsPerMm = focalPixels / (v.distance * 1000.0);
  v.heightPixels = kCharacterHeightMetres * 1000.0 * v.pixelsPerMm;
  // In view: the angle off the view axis within the field of view, widened by the figure's own size
  // and the image's width (taken as 16:9), so that a character half in view still counts.
  const double lateral = (toCharacter - v.distance * forward).norm();
  const double halfExtent = tanHalf * v.distance * (16.0 / 9.0) + kCharacterHeightMetres;
  v.inView = lateral <= halfExtent;
  return v;
}

uint32_t levelIndex(const QualityLadder& ladder, const std::string& nameOrIndex, const std::string& what) {
  for (size_t i = 0; i < ladder.size(); ++i)
    if (ladder[i].name == nameOrIndex) return uint32_t(i);
  if (!nameOrIndex.empty() && nameOrIndex.find_first_not_of("0123456789") == std::string::npos &&
      nameOrIndex.size() < 4) {
    const uint32_t i = uint32_t(std::stoul(nameOrIndex));
    if (i < ladder.size()) return i;
  }
  std::string offered;
  for (size_t i = 0; i < ladder.size(); ++i) {
    if (i > 0) offered += ", ";
    offered += std::to_string(i);
    offered += " " + ladder[i].name;
  }
  throw Error(what + ": no level '" + nameOrIndex + "' (the model's levels: " + offered + ")");
}

LevelPlanner::LevelPlanner(std::vector<const QualityLadder*> ladders, std::vector<std::optional<uint32_t>> fixedLevels,
                           const LevelPlannerSettings& settings)
    : ladders_(std::move(ladders)), fixed_(std::move(fixedLevels)), settings_(settings) {
  if (fixed_.empty()) fixed_.resize(ladders_.size());
  if (fixed_.size() != ladders_.size()) throw Error("level planner: fixed levels for another number of characters");
  for (size_t c = 0; c < ladders_.size(); ++c) {
    if (!ladders_[c] || ladders_[c]->empty())
      throw Error("level planner: character " + std::to_string(c) + " has no ladder");
    if (fixed_[c] && *fixed_[c] >= ladders_[c]->size())
      throw Error("level planner: character " + std::to_string(c) + " fixed at level " + std::to_string(*fixed_[c]) +
                  " of a ladder of " + std::to_string(ladders_[c]->size()));
  }
  if (settings_.frameBudgetMs && !(*settings_.frameBudgetMs > 0.0))
    throw Error("level planner: the frame budget must be a positive number of milliseconds");
  if (settings_.tolerancePixels && !(*settings_.tolerancePixels > 0.0))
    throw Error("level planner: the pixel tolerance must be positive");
  current_.assign(ladders_.size(), 0);
  lastChange_.assign(ladders_.size(), std::nullopt);
  out_.characters.resize(ladders_.size());
}

void LevelPlanner::setCosts(LevelCosts costs) {
  if (!costs.empty()) {
    if (costs.msPerCharacter.size() != ladders_.size())
      throw Error("level planner: costs for " + std::to_string(costs.msPerCharacter.size()) + " characters, " +
                  std::to_string(ladders_.size()) + " planned");
    for (size_t c = 0; c < ladders_.size(); ++c)
      if (costs.msPerCharacter[c].size() != ladders_[c]->size())
        throw Error("level planner: costs of character " + std::to_string(c) + " do not cover its ladder");
  }
  // A cheaper level does no more work than the one before it: measured costs that say otherwise are
  // noise, and would stop the budget's descent at a level that seems to save nothing.
  for (auto& perLevel : costs.msPerCharacter)
    for (size_t l = 1; l < perLevel.size(); ++l) perLevel[l] = std::min(perLevel[l], perLevel[l - 1]);
  costs_ = std::move(costs);
}

double LevelPlanner::errorOf(size_t c, uint32_t level) const { return (*ladders_[c])[level].vertexMeanMm; }

double LevelPlanner::costOf(size_t c, uint32_t level) const { return scale_ * costs_.msPerCharacter[c][level]; }

void LevelPlanner::setCostScale(double scale) {
  if (!(scale > 0.0 && std::isfinite(scale))) throw Error("level planner: the cost scale must be positive and finite");
  scale_ = scale;
}

const PlannedLevels& LevelPlanner::plan(uint64_t frame, std::span<const Eigen::Vector3d> roots) {
  const size_t n = ladders_.size();
  if (roots.size() != n)
    throw Error("level planner: " + std::to_string(roots.size()) + " roots for " + std::to_string(n) + " characters");
  std::vector<uint32_t> level(n, 0);
  std::vector<bool> movable(n, false);
  for (size_t c = 0; c < n; ++c) {
    LevelChoice& ch = out_.characters[c];
    ch.view = viewOf(settings_.camera, roots[c]);
    const QualityLadder& ladder = *ladders_[c];
    if (fixed_[c]) {
      level[c] = *fixed_[c];
      ch.reason = "fixed (the scene's level or --level)";
      continue;
    }
    const bool held = !first_ && lastChange_[c] && frame < *lastChange_[c] + settings_.holdFrames;
    if (held) {
      level[c] = current_[c];
      ch.reason = "held (changed " + std::to_string(frame - *lastChange_[c]) + " frames ago, hold " +
                  std::to_string(settings_.holdFrames) + ")";
      continue;
    }
    movable[c] = true;
    level[c] = 0;
    ch.reason = "full quality";
    // Without a tolerance every character starts at full quality (a budget then steps the ones out of
    // view down first: their weight is 0).
    if (settings_.tolerancePixels && !ch.view.inView) {
      level[c] = uint32_t(ladder.size() - 1);
      ch.reason = "out of view";
    } else if (settings_.tolerancePixels && ladder.measured()) {
      // The cheapest level whose mean error on screen is within the tolerance.
      for (uint32_t l = 0; l < ladder.size(); ++l) {
        const double px = ladder[l].vertexMeanMm * ch.view.pixelsPerMm;
        if (std::isfinite(px) && px <= *settings_.tolerancePixels) {
          level[c] = l;
          ch.reason = fixed1(ch.view.heightPixels) + " px tall: " + ladder[l].name + " is within " +
                      fixed1(*settings_.tolerancePixels) + " px on screen";
        }
      }
    }
  }

  // The budget. Each movable character's best level is the one chosen above (full quality, or what the
  // tolerance allows); with a budget it starts from where it is (its level last frame, never better than
  // its best), then: above the budget, step down the character whose next level costs the least
  // screen-weighted error per millisecond saved, until it fits; below kHeadroom of the budget, step up
  // the one whose better level buys the most error per millisecond while the total stays below that.
  // Between the two nothing moves: a dead band, so that a prediction near the budget does not make
  // characters trade levels back and forth.
  constexpr double kHeadroom = 0.85;
  out_.overBudget = false;
  out_.predictedMs = out_.unscaledMs = std::numeric_limits<double>::quiet_NaN();
  if (!costs_.empty()) {
    std::vector<uint32_t> best = level;
    if (settings_.frameBudgetMs && !first_)
      for (size_t c = 0; c < n; ++c)
        if (movable[c]) level[c] = std::max(level[c], current_[c]);
    double total = 0;
    for (size_t c = 0; c < n; ++c) total += costOf(c, level[c]);
    if (settings_.frameBudgetMs) {
      const double budget = *settings_.frameBudgetMs;
      std::vector<int> moved(n, 0);
      // Screen-weighted error added by moving character c from level a to level b (b > a: down).
      const auto addedError = [&](size_t c, uint32_t a, uint32_t b) {
        double e = errorOf(c, b) - errorOf(c, a);
        if (!std::isfinite(e)) e = double(b) - double(a);  // an unmeasured ladder: one step of error per step
        return e * out_.characters[c].view.weight();
      };
      while (total > budget) {
        size_t pick = n;
        double pickScore = std::numeric_limits<double>::infinity();
        uint32_t pickTo = 0;
        for (size_t c = 0; c < n; ++c) {
          if (!movable[c]) continue;
          // The next level that costs less (levels of equal cost are passed over: they save nothing).
          uint32_t to = level[c] + 1;
          while (to < ladders_[c]->size() && !(costOf(c, to) < costOf(c, level[c]))) ++to;
          if (to >= ladders_[c]->size()) continue;
          const double saved = costOf(c, level[c]) - costOf(c, to);
          const double score = std::max(addedError(c, level[c], to), 0.0) / saved;
          if (score < pickScore) pickScore = score, pick = c, pickTo = to;
        }
        if (pick == n) {
          out_.overBudget = true;
          break;
        }
        total -= costOf(pick, level[pick]) - costOf(pick, pickTo);
        level[pick] = pickTo;
        --moved[pick];
      }
      while (!first_ && !out_.overBudget) {
        size_t pick = n;
        double pickScore = 0;
        for (size_t c = 0; c < n; ++c) {
          if (!movable[c] || level[c] <= best[c]) continue;
          const double extra = costOf(c, level[c] - 1) - costOf(c, level[c]);
          if (total + std::max(extra, 0.0) > kHeadroom * budget) continue;
          const double gained = -addedError(c, level[c], level[c] - 1);
          const double score = gained / std::max(extra, 1e-9);
          if (score > pickScore) pickScore = score, pick = c;
        }
        if (pick == n) break;
        total += costOf(pick, level[pick] - 1) - costOf(pick, level[pick]);
        --level[pick];
        ++moved[pick];
      }
      for (size_t c = 0; c < n; ++c) {
        if (!movable[c]) continue;
        const std::string size = fixed1(out_.characters[c].view.heightPixels) + " px tall: ";
        if (moved[c] < 0 || (level[c] > best[c] && moved[c] == 0))
          out_.characters[c].reason = size + "below its best level to fit the budget of " + fixed1(budget) + " ms";
        else if (moved[c] > 0)
          out_.characters[c].reason =
              size + "stepped up: the frame has room in the budget of " + fixed1(budget) + " ms";
      }
    }
    out_.predictedMs = total;
    out_.unscaledMs = total / scale_;
  }

  double wSum = 0, wErr = 0, wFull = 0;
  for (size_t c = 0; c < n; ++c) {
    LevelChoice& ch = out_.characters[c];
    ch.changed = !first_ && level[c] != current_[c];
    if (ch.changed) lastChange_[c] = frame;
    current_[c] = level[c];
    ch.level = level[c];
    const double w = ch.view.weight();
    wSum += w;
    wErr += w * errorOf(c, level[c]);
    wFull += w * errorOf(c, 0);
  }
  out_.weightedErrorMm = wSum > 0 ? wErr / wSum : std::numeric_limits<double>::quiet_NaN();
  out_.fullErrorMm = wSum > 0 ? wFull / wSum : std::numeric_limits<double>::quiet_NaN();
  first_ = false;
  return out_;
}

}  // namespace swish::runtime
