#include "swish/replay/character_motion.hpp"

#include <cmath>

#include "swish/core/error.hpp"
#include "swish/core/rotation.hpp"

namespace swish::replay {

CharacterMotion::CharacterMotion(std::shared_ptr<const AnimationClip> clip, const runtime::SceneClip& playback,
                                 const Skeleton& skeleton, std::string character)
    : clip_(std::move(clip)), playback_(playback), skeleton_(&skeleton), character_(std::move(character)) {
  if (!clip_ || clip_->frames.empty()) throw Error("character '" + character_ + "': the animation clip has no frames");
  for (const Pose& p : clip_->frames)
    if (p.local.size() != skeleton.size())
      throw Error("character '" + character_ + "': the clip '" + clip_->name + "' does not fit the model's skeleton");
  lastRoot_ = skeleton.restPose().rootTranslation;
}

CharacterMotion::CharacterMotion(std::shared_ptr<const PoseStream> stream, const Skeleton& skeleton,
                                 std::string character)
    : stream_(std::move(stream)), skeleton_(&skeleton), character_(std::move(character)) {
  if (!stream_ || stream_->frames.empty()) throw Error("character '" + character_ + "': the pose stream has no frames");
  streamJointOf_.assign(skeleton.size(), -1);
  for (size_t s = 0; s < stream_->joints.size(); ++s) {
    const int j = skeleton.find(stream_->joints[s]);
    if (j >= 0) streamJointOf_[size_t(j)] = int(s);
  }
  lastRoot_ = skeleton.restPose().rootTranslation;
}

Pose CharacterMotion::clipPose(double seconds) const {
  const AnimationClip& c = *clip_;
  const double fps = c.framesPerSecond > 0 ? c.framesPerSecond : 30.0;
  const double duration = double(c.frames.size()) / fps;
  double t = std::fmod(playback_.timeOffsetSeconds + playback_.speed * seconds, duration);
  if (t < 0) t += duration;
  const double f = t * fps;
  const size_t f0 = std::min(size_t(f), c.frames.size() - 1), f1 = (f0 + 1) % c.frames.size();
  const float w = float(f - double(f0));
  const Pose& a = c.frames[f0];
  const Pose& b = c.frames[f1];
  Pose p;
  p.local.resize(a.local.size());
  for (size_t j = 0; j < a.local.size(); ++j) p.local[j] = slerpShortest(a.local[j], b.local[j], w);
  // No root blend across the wrap: the clip jumps back to its start there.
  p.rootTranslation = f1 == 0 ? a.rootTranslation : Vec3f(a.rootTranslation * (1.f - w) + b.rootTranslation * w);
  return p;
}

Pose CharacterMotion::streamPose(double seconds, uint32_t frame, std::vector<PoseIssue>& issues) {
  const PoseStream& s = *stream_;
  size_t f = size_t(std::llround(std::max(0.0, seconds * s.framesPerSecond)));
  if (f >= s.frames.size()) {
    if (!reportedEnd_)
      issues.push_back({frame, character_, "",
                        "the pose stream ends after " + std::to_string(s.frames.size()) + " frames",
                        "its last frame is held"});
    reportedEnd_ = true;
    f = s.frames.size() - 1;
  }
  const PoseStreamFrame& sf = s.frames[f];
  Pose p = skeleton_->restPose();
  for (size_t j = 0; j < skeleton_->size(); ++j) {
    const int sj = streamJointOf_[j];
    if (sj < 0) {
      if (!reportedUnnamed_)
        issues.push_back(
            {frame, character_, skeleton_->joints[j].name, "joint not in the pose stream", "rest rotation"});
      continue;
    }
    if (!sf.present[size_t(sj)]) {
      issues.push_back({frame, character_, skeleton_->joints[j].name, "joint missing in this frame", "rest rotation"});
      continue;
    }
    p.local[j] = sf.rotations[size_t(sj)];
  }
  reportedUnnamed_ = true;
  p.rootTranslation = sf.root;
  return p;
}

void CharacterMotion::sanitise(Pose& p, uint32_t frame, std::vector<PoseIssue>& issues) {
  for (size_t j = 0; j < p.local.size(); ++j) {
    const SanitizedQuat s = sanitizeQuaternion(p.local[j]);
    if (s.status == QuatStatus::Invalid) {
      issues.push_back({frame, character_, skeleton_->joints[j].name, "NaN/Inf or zero quaternion", "rest rotation"});
      p.local[j] = skeleton_->joints[j].rest.rotation;
    } else {
      if (s.status == QuatStatus::Renormalised)
        issues.push_back({frame, character_, skeleton_->joints[j].name,
                          "non-unit quaternion (norm " + std::to_string(p.local[j].norm()) + ")", "normalised"});
      p.local[j] = s.q;
    }
  }
  if (!p.rootTranslation.allFinite()) {
    issues.push_back({frame, character_, "", "non-finite root translation", "last finite root kept"});
    p.rootTranslation = lastRoot_;
  }
  lastRoot_ = p.rootTranslation;
}

Pose CharacterMotion::poseAt(double seconds, uint32_t frame, std::vector<PoseIssue>& issues) {
  Pose p = clip_ ? clipPose(seconds) : streamPose(seconds, frame, issues);
  sanitise(p, frame, issues);
  return p;
}

}  // namespace swish::replay
