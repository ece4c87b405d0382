#pragma once
// Where a scene character's pose comes from, frame by frame: an animation clip (retargeted onto the
// model's skeleton by io::importAnimation; sampled at offset + speed * time, wrapping around the clip,
// interpolated between frames) or a recorded pose stream (pose_stream.hpp; frame round(time * fps),
// holding the last frame after the end).
//
// Bad poses never stop the replay; each is reported with its scene frame, character and joint
// (PoseIssue), and handled so:
//   - a NaN/Inf quaternion, or one of norm < 1e-6:  the joint takes its REST rotation;
//   - a non-unit quaternion (norm off by > 1e-3):    normalised (core's sanitizeQuaternion);
//   - a joint missing from a frame (null / absent): its rest rotation;
//   - a skeleton joint the stream never names:       its rest rotation (reported once, on the first frame);
//   - a non-finite root translation:                 the last finite root (the rest root at first);
//   - a stream shorter than the scene:               its last frame is held (reported once).
// The poses handed on are therefore always finite and unit, and the runtime's own Theta checks see
// clean input.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swish/core/character.hpp"
#include "swish/replay/pose_stream.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct PoseIssue {
  uint32_t frame = 0;  // scene frame
  std::string character;
  std::string joint;  // "" for the whole pose (root, stream end)
  std::string problem;
  std::string action;
};

class CharacterMotion {
 public:
  // `clip` must already be on `skeleton` (io::importAnimation); shared between characters.
  CharacterMotion(std::shared_ptr<const AnimationClip> clip, const runtime::SceneClip& playback,
                  const Skeleton& skeleton, std::string character);
  CharacterMotion(std::shared_ptr<const PoseStream> stream, const Skeleton& skeleton, std::string character);

  // The pose at scene time `seconds` (scene frame `frame`, for reports), sanitised; issues appended.
  Pose poseAt(double seconds, uint32_t frame, std::vector<PoseIssue>& issues);

 private:
  Pose clipPose(double seconds) const;
  Pose streamPose(double seconds, uint32_t frame, std::vector<PoseIssue>& issues);
  void sanitise(Pose& pose, uint32_t frame, std::vector<PoseIssue>& issues);

  std::shared_ptr<const AnimationClip> clip_;
  runtime::SceneClip playback_;
  std::shared_ptr<const PoseStream> stream_;
  std::vector<int> streamJointOf_;  // per skeleton joint: its index in the stream, or -1
  const Skeleton* skeleton_;
  std::string character_;
  Vec3f lastRoot_;
  bool reportedUnnamed_ = false, reportedEnd_ = false;
};

}  // namespace swish::replay
