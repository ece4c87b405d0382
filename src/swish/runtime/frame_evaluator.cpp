#include "swish/runtime/frame_evaluator.hpp"

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
  const size_t size = 6 * inputJoints_.size();
  issueScratch_.clear();  // keeps its capacity: a clean frame allocates nothing
  computeTheta(inputJoints_, localRotations, std::span<float>(theta_.data() + c * size, size), &issueScratch_);
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
  mlp_.evaluateBatchSplit(theta_, out_.meshWeights, out_.normalCodes, characters_);
  const double tm = now();
  if (guard_.active()) {
    guard_.measure(theta_, characters_, out_.novelty);
    const size_t k = out_.meshComponents;
    const bool on = guardOn();
    for (uint32_t c = 0; c < characters_; ++c) {
      if (!(out_.novelty[c] <= guard_.guard().flagAbove)) out_.novel.push_back(c);
      out_.guardBlend[c] = on ? guard_.blendOf(out_.novelty[c]) : 0.f;
      if (on) guard_.apply(out_.novelty[c], std::span<float>(out_.meshWeights.data() + c * k, k));
    }
  }
  const double t2 = now();
  double t3 = t2;
  if (search_) {
    const size_t cd = out_.codeDims;
    for (uint32_t c = 0; c < characters_; ++c) {
      // Fallback for a non-finite code: the map this character shows now (0 before its first frame).
      const uint32_t previous = filters_[c].hasHistory() ? out_.mapIndex[c] : 0u;
      const NearestCode r = search_->find(std::span<const float>(out_.normalCodes.data() + c * cd, cd), previous);
      if (!r.found) out_.nonFiniteCode.push_back(c);
      out_.mapIndex[c] = r.index;
    }
    t3 = now();
    for (uint32_t c = 0; c < characters_; ++c) {
      const BlendStep s = filters_[c].step(dt.size() == 1 ? dt[0] : dt[c], out_.mapIndex[c]);
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
