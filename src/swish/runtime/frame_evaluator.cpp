#include "swish/runtime/frame_evaluator.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

namespace {
double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

const Model& validated(const Model& model) {
  model.validate("frame evaluator: model");
  return model;
}
}  // namespace

FrameEvaluator::FrameEvaluator(const Model& model, uint32_t characters, CpuKernel kernel)
    : FrameEvaluator(model, characters, FrameEvaluatorOptions{kernel, true, true}) {}

FrameEvaluator::FrameEvaluator(const Model& model, uint32_t characters, const FrameEvaluatorOptions& options)
    : inputJoints_(validated(model).inputJoints),
      rootGravity_(model.rootGravity),
      characters_(characters),
      joints_(uint32_t(model.skeleton.size())),
      mlp_(model, options.kernel),
      guard_(model),
      guardOn_(options.guard) {
  if (!model.normalMaps.empty() && options.normalMaps) search_.emplace(model.normalMaps.keys, options.kernel);
  filters_.assign(characters, TemporalFilter(model.temporalFilter.timeConstantSeconds));
  theta_.resize(size_t(characters) * size_t(model.thetaSize()));
  out_.characters = characters;
  out_.meshComponents = uint32_t(mlp_.meshComponents());
  out_.codeDims = uint32_t(mlp_.normalCodeDims());
  out_.meshWeights.resize(size_t(characters) * out_.meshComponents);
  out_.normalCodes.resize(size_t(characters) * out_.codeDims);
  out_.mapIndex.assign(characters, search_ ? 0u : kNoMap);
  out_.blendAlpha.assign(characters, 0.f);
  if (search_) out_.blend.resize(characters);
  out_.novelty.assign(characters, std::numeric_limits<float>::quiet_NaN());
  out_.guardBlend.assign(characters, 0.f);
  levels_.assign(characters, LevelUse{out_.meshComponents, true});
}

void FrameEvaluator::setLevel(uint32_t character, const QualityLevel& level) {
  if (character >= characters_)
    throw Error("frame evaluator: level for character " + std::to_string(character) + " of " +
                std::to_string(characters_));
  if (level.meshComponents > out_.meshComponents)
    throw Error("frame evaluator: level " + level.name + " reads " + std::to_string(level.meshComponents) +
                " mesh components, the model has " + std::to_string(out_.meshComponents));
  LevelUse& use = levels_[character];
  // A map that comes back after frames without one starts from the new selection, not from a map
  // the character stopped showing.
  if (level.normalMaps && !use.normalMaps) filters_[character].reset();
  use = {level.meshComponents, level.normalMaps};
}

void FrameEvaluator::resetCharacter(uint32_t character) {
  if (character >= characters_)
    throw Error("frame evaluator: character " + std::to_string(character) + " of " + std::to_string(characters_));
  filters_[character].reset();
}

void FrameEvaluator::beginFrame() {
  out_.jointIssues.clear();
  out_.nonFiniteCode.clear();
  out_.invalidDt.clear();
  out_.novel.clear();
}

void FrameEvaluator::thetaOf(uint32_t c, std::span<const Quatf> localRotations) {
  const size_t size = thetaSize(inputJoints_.size(), rootGravity_);
  issueScratch_.clear();  // keeps its capacity: a clean frame allocates nothing
  computeTheta(inputJoints_, rootGravity_, localRotations, std::span<float>(theta_.data() + c * size, size),
               &issueScratch_);
  for (const ThetaJointIssue& i : issueScratch_) out_.jointIssues.push_back({c, i});
}

const FrameOutput& FrameEvaluator::evaluate(std::span<const Quatf> rotations, std::span<const float> dtSeconds) {
  if (rotations.size() != size_t(characters_) * joints_)
    throw Error("frame evaluator: " + std::to_string(rotations.size()) + " rotations for " +
                std::to_string(characters_) + " characters of " + std::to_string(joints_) + " joints");
  const double t0 = now();
  beginFrame();
  for (uint32_t c = 0; c < characters_; ++c) thetaOf(c, rotations.subspan(size_t(c) * joints_, joints_));
  return finishFrame(dtSeconds, t0);
}

const FrameOutput& FrameEvaluator::evaluate(std::span<const Quatf> rotations, float dtSeconds) {
  return evaluate(rotations, std::span<const float>(&dtSeconds, 1));
}

const FrameOutput& FrameEvaluator::evaluate(std::span<const Pose> poses, float dtSeconds) {
  if (poses.size() != characters_)
    throw Error("frame evaluator: " + std::to_string(poses.size()) + " poses for " + std::to_string(characters_) +
                " characters");
  const double t0 = now();
  beginFrame();
  for (uint32_t c = 0; c < characters_; ++c) {
    if (poses[c].local.size() != joints_)
      throw Error("frame evaluator: pose of character " + std::to_string(c) + " has " +
                  std::to_string(poses[c].local.size()) + " rotations, the skeleton " + std::to_string(joints_) +
                  " joints");
    thetaOf(c, poses[c].local);
  }
  return finishFrame(std::span<const float>(&dtSeconds, 1), t0);
}

const FrameOutput& FrameEvaluator::finishFrame(std::span<const float> dt, double t0) {
  if (dt.size() != 1 && dt.size() != characters_)
    throw Error("frame evaluator: " + std::to_string(dt.size()) + " dt values for " + std::to_string(characters_) +
                " characters (give one, or one per character)");
  const double t1 = now();
  const size_t k = out_.meshComponents, cd = out_.codeDims;
  networkRows_.clear();
  for (uint32_t c = 0; c < characters_; ++c)
    if (levels_[c].components > 0 || levels_[c].normalMaps) networkRows_.push_back(c);
  if (networkRows_.size() == characters_) {
    mlp_.evaluateBatchSplit(theta_, out_.meshWeights, out_.normalCodes, characters_);
  } else {
    // Only the characters whose level needs the network run it: compact their rows, then scatter.
    const size_t ts = theta_.size() / std::max<size_t>(characters_, 1), n = networkRows_.size();
    thetaNet_.resize(n * ts);
    weightsNet_.resize(n * k);
    codesNet_.resize(n * cd);
    for (size_t r = 0; r < n; ++r) std::copy_n(theta_.begin() + networkRows_[r] * ts, ts, thetaNet_.begin() + r * ts);
    if (n > 0) mlp_.evaluateBatchSplit(thetaNet_, weightsNet_, codesNet_, uint32_t(n));
    std::fill(out_.meshWeights.begin(), out_.meshWeights.end(), 0.f);
    std::fill(out_.normalCodes.begin(), out_.normalCodes.end(), 0.f);
    for (size_t r = 0; r < n; ++r) {
      std::copy_n(weightsNet_.begin() + r * k, k, out_.meshWeights.begin() + networkRows_[r] * k);
      std::copy_n(codesNet_.begin() + r * cd, cd, out_.normalCodes.begin() + networkRows_[r] * cd);
    }
  }
  const double tm = now();
  if (guard_.active()) {
    guard_.measure(theta_, characters_, out_.novelty);
    const bool on = guardOn();
    for (uint32_t c = 0; c < characters_; ++c) {
      if (!(out_.novelty[c] <= guard_.guard().flagAbove)) out_.novel.push_back(c);
      out_.guardBlend[c] = on ? guard_.blendOf(out_.novelty[c]) : 0.f;
      if (on) guard_.apply(out_.novelty[c], std::span<float>(out_.meshWeights.data() + c * k, k));
    }
  }
  // A level reads the leading components only: the rest are 0 for every consumer (the GPU, the CPU
  // reference, a host), not only for the deform.
  for (uint32_t c = 0; c < characters_; ++c)
    std::fill(out_.meshWeights.begin() + c * k + levels_[c].components, out_.meshWeights.begin() + (c + 1) * k, 0.f);
  const double t2 = now();
  double t3 = t2;
  if (search_) {
    for (uint32_t c = 0; c < characters_; ++c) {
      if (!levels_[c].normalMaps) {
        out_.mapIndex[c] = kNoMap;
        continue;
      }
      // Fallback for a non-finite code: the map this character shows now (0 before its first frame).
      const uint32_t previous = filters_[c].hasHistory() ? out_.mapIndex[c] : 0u;
      const NearestCode r = search_->find(std::span<const float>(out_.normalCodes.data() + c * cd, cd), previous);
      if (!r.found) out_.nonFiniteCode.push_back(c);
      out_.mapIndex[c] = r.index;
    }
    t3 = now();
    for (uint32_t c = 0; c < characters_; ++c) {
      const float d = dt.size() == 1 ? dt[0] : dt[c];
      if (!levels_[c].normalMaps) {
        if (!(d >= 0.f)) out_.invalidDt.push_back(c);
        out_.blend[c] = BlendStep{kNoMap, 0.f, false, !(d >= 0.f)};
        out_.blendAlpha[c] = 0.f;
        continue;
      }
      const BlendStep s = filters_[c].step(d, out_.mapIndex[c]);
      if (s.invalidDt) out_.invalidDt.push_back(c);
      out_.blend[c] = s;
      out_.blendAlpha[c] = s.alpha;
    }
  } else {
    for (uint32_t c = 0; c < characters_; ++c) {
      const float d = dt.size() == 1 ? dt[0] : dt[c];
      if (!(d >= 0.f)) out_.invalidDt.push_back(c);
    }
  }
  const double t4 = now();
  out_.timings = {t1 - t0, tm - t1, t2 - tm, t3 - t2, t4 - t3, t4 - t0};
  return out_;
}

}  // namespace swish::runtime
