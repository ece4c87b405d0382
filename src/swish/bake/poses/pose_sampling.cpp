#include "swish/bake/poses/pose_sampling.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/core/rotation.hpp"

namespace swish::bake {
namespace {

std::vector<int> mirrorMap(const Skeleton& skeleton) {
  std::vector<int> map(skeleton.size());
  for (size_t j = 0; j < skeleton.size(); ++j) {
    const int m = skeleton.find(mirroredJointName(skeleton.joints[j].name));
    map[j] = m >= 0 ? m : int(j);
  }
  return map;
}

inline Quatf reflectX(const Quatf& q) { return Quatf(q.w(), q.x(), -q.y(), -q.z()); }

void checkClip(const Skeleton& skeleton, const AnimationClip& clip, size_t index) {
  const std::string what = "clip " + std::to_string(index) + " '" + clip.name + "'";
  if (clip.frames.empty()) throw Error(what + " has no frames");
  if (!(clip.framesPerSecond > 0.f) || !std::isfinite(clip.framesPerSecond))
    throw Error(what + " has frame rate " + std::to_string(clip.framesPerSecond));
  for (size_t f = 0; f < clip.frames.size(); ++f)
    if (clip.frames[f].local.size() != skeleton.size())
      throw Error(what + ", frame " + std::to_string(f) + ": " + std::to_string(clip.frames[f].local.size()) +
                  " rotations for a skeleton of " + std::to_string(skeleton.size()) + " joints");
}

// Local rotation of `joint` at a fractional frame (shortest-arc slerp between neighbouring frames).
Quatf rotationAt(const AnimationClip& clip, int joint, float frame) {
  const size_t last = clip.frames.size() - 1;
  const float f = std::clamp(frame, 0.f, float(last));
  const size_t f0 = std::min(size_t(f), last);
  const size_t f1 = std::min(f0 + 1, last);
  const float t = f - float(f0);
  const Quatf& a = clip.frames[f0].local[size_t(joint)];
  if (t <= 0.f || f0 == f1) return a;
  return slerpShortest(a, clip.frames[f1].local[size_t(joint)], t);
}

}  // namespace

Pose mirrorPose(const Skeleton& skeleton, const Pose& pose) {
  const auto map = mirrorMap(skeleton);
  Pose out = pose;
  for (size_t j = 0; j < skeleton.size(); ++j) out.local[j] = reflectX(pose.local[size_t(map[j])]);
  out.rootTranslation.x() = -pose.rootTranslation.x();
  return out;
}

Pose poseOfSample(const Skeleton& skeleton, const std::vector<AnimationClip>& clips,
                  const PoseSamples::Origin& origin) {
  if (origin.clip >= clips.size())
    throw Error("pose sample refers to clip " + std::to_string(origin.clip) + " of " + std::to_string(clips.size()));
  const AnimationClip& clip = clips[origin.clip];
  checkClip(skeleton, clip, origin.clip);
  Pose p;
  p.local.resize(skeleton.size());
  for (size_t j = 0; j < skeleton.size(); ++j) p.local[j] = rotationAt(clip, int(j), origin.frame);
  const size_t f0 = std::min(size_t(std::max(origin.frame, 0.f)), clip.frames.size() - 1);
  p.rootTranslation = clip.frames[f0].rootTranslation;
  return origin.mirrored ? mirrorPose(skeleton, p) : p;
}

PoseSamples samplePoses(const Skeleton& skeleton, const std::vector<AnimationClip>& clips,
                        const PoseSamplingOptions& options) {
  if (clips.empty()) throw Error("pose sampling: no clips");
  if (options.joints.empty()) throw Error("pose sampling: no joints chosen");
  if (options.characters == 0) throw Error("pose sampling: zero characters");
  if (!(options.sampleRate >= 0.0) || !(options.secondsPerCharacter >= 0.0))
    throw Error("pose sampling: sample rate and duration must be >= 0");
  for (size_t c = 0; c < clips.size(); ++c) checkClip(skeleton, clips[c], c);
  const std::vector<double>& weights = options.clipWeights;
  if (!weights.empty() && weights.size() != clips.size())
    throw Error("pose sampling: " + std::to_string(weights.size()) + " clip weights for " +
                std::to_string(clips.size()) + " clips");
  double weightSum = 0.0;
  for (double w : weights) {
    if (!(w > 0.0) || !std::isfinite(w)) throw Error("pose sampling: clip weights must be > 0");
    weightSum += w;
  }
  auto weightOf = [&](size_t clip) { return weights.empty() ? 1.0 : weights[clip]; };
  // A clip drawn with probability proportional to its weight (uniform, as before weights, without them).
  auto drawClip = [&](Rng& rng) -> uint32_t {
    if (weights.empty()) return uint32_t(rng.below(clips.size()));
    double x = rng.uniform(0.0, weightSum);
    for (size_t i = 0; i < weights.size(); ++i) {
      if (x < weights[i]) return uint32_t(i);
      x -= weights[i];
    }
    return uint32_t(weights.size() - 1);
  };

  std::vector<int> joints, mirroredJoints;
  const auto mirror = mirrorMap(skeleton);
  for (const auto& name : options.joints) {
    const int j = skeleton.find(name);
    if (j < 0) throw Error("pose sampling: joint '" + name + "' is not in the skeleton");
    joints.push_back(j);
    mirroredJoints.push_back(mirror[size_t(j)]);
  }

  PoseSamples out;
  out.dim = int(joints.size()) * 6;
  auto emit = [&](uint32_t character, uint32_t clipIndex, float frame, bool mirrored) {
    const AnimationClip& clip = clips[clipIndex];
    for (size_t k = 0; k < joints.size(); ++k) {
      Quatf q = rotationAt(clip, mirrored ? mirroredJoints[k] : joints[k], frame);
      if (mirrored) q = reflectX(q);
      const Rot6 r = toRot6(q);
      out.values.insert(out.values.end(), r.begin(), r.end());
    }
    out.origins.push_back({character, clipIndex, frame, mirrored});
  };

  const Rng base(options.seed);
  for (uint32_t c = 0; c < options.characters; ++c) {
    Rng rng = base.split(c);
    const bool mirrored = options.mirrorOddCharacters && (c % 2 == 1);
    const double speed = c == 0 ? 1.0 : 1.0 + double(options.speedJitter) * rng.uniform(-1.0, 1.0);
    if (options.secondsPerCharacter <= 0.0) {
      // Every clip once, in order, from its first frame to its last.
      for (uint32_t ci = 0; ci < clips.size(); ++ci) {
        const AnimationClip& clip = clips[ci];
        const double rate = options.sampleRate > 0 ? options.sampleRate : clip.framesPerSecond;
        const double step = speed * clip.framesPerSecond / (rate * weightOf(ci));
        const double last = double(clip.frames.size() - 1);
        for (double f = 0.0; f <= last + 1e-9; f += step) emit(c, ci, float(f), mirrored);
      }
      continue;
    }
    // A recording of the given length: clips one after another in random order, the first one
    // entered at a random frame (character 0 starts at clip 0, frame 0).
    uint32_t ci = c == 0 ? 0 : drawClip(rng);
    double frame = c == 0 ? 0.0 : rng.uniform(0.0, double(clips[ci].frames.size() - 1));
    const double rate = options.sampleRate > 0 ? options.sampleRate : clips[0].framesPerSecond;
    const size_t count = size_t(std::llround(options.secondsPerCharacter * rate));
    for (size_t s = 0; s < count; ++s) {
      emit(c, ci, float(frame), mirrored);
      frame += speed * clips[ci].framesPerSecond / rate;
      if (frame > double(clips[ci].frames.size() - 1)) {
        ci = drawClip(rng);
        frame = 0.0;
      }
    }
  }
  return out;
}

}  // namespace swish::bake
