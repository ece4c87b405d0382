#pragma once
// Theta, the network's input (paper section 2.1): the 6D rotation representation (Zhou et al. 2020) of
// the model's input joints, in the model's order, 6 floats per joint, with core/rotation.hpp's toRot6
// convention ([R00, R10, R20, R01, R11, R21], identity -> [1,0,0, 0,1,0]); then, in models that ask
// for it (Model::rootGravity), the gravity direction in the root joint's frame, R_root^-1 (0, -1, 0):
// 3 floats that tell the body's lean against gravity, which no joint's local rotation holds (part 1's
// own datasets are simulated upright, so a bake refuses it on them: docs/baking.md). The
// root is skeleton joint 0 (parents come first); its heading (a turn about +Y) does not change it.
//
// Policy for quaternions that arrive from outside (animation files, a host engine), documented here and
// applied through core's sanitizeQuaternion:
//   - Only the model's input joints are read and sanitised; the other joints of the skeleton do not enter
//     Theta (skinning reads them, and sanitises them there).
//   - A finite quaternion with a norm of at least 1e-6 is divided by its norm. If the norm was off by
//     more than 1e-3 the joint is reported as Renormalised.
//   - A quaternion with a NaN/Inf component, or a norm below 1e-6, has no rotation one could recover:
//     it is replaced by the identity and reported as Invalid.
//   - q and -q are the same rotation and give the same 6D vector, so no sign convention is imposed.
// Reports are never silent: every joint that was not Ok is listed with its skeleton index and its slot
// in Theta, so the caller can report it with the frame and the character.
#include <cstdint>
#include <span>
#include <vector>

#include "swish/core/rotation.hpp"
#include "swish/core/types.hpp"
#include "swish/model/model.hpp"  // thetaSize

namespace swish::runtime {

struct ThetaJointIssue {
  uint32_t skeletonJoint = 0;          // index into the skeleton (what Pose::local is indexed by)
  uint32_t inputSlot = 0;              // position among the model's input joints (Theta floats 6*slot .. 6*slot+5)
  QuatStatus status = QuatStatus::Ok;  // Renormalised or Invalid
};

struct ThetaReport {
  uint32_t renormalised = 0;  // joints whose quaternion was visibly non-unit and was normalised
  uint32_t invalid = 0;       // joints replaced by the identity
  bool clean() const { return renormalised == 0 && invalid == 0; }
};

// Builds Theta for one character (without the gravity values). `localRotations` are the local rotations of the whole
// skeleton (as in Pose::local); `inputJoints` the model's input joints (Model::inputJoints). `theta` must hold exactly
// 6 * inputJoints.size() floats. Issues are appended to `issues` when it is not null (no allocation when
// every joint is clean). Throws Error if a joint index is outside `localRotations` or `theta` has the
// wrong size: those are programming errors of the caller, not bad data.
ThetaReport computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                         std::span<float> theta, std::vector<ThetaJointIssue>* issues = nullptr);

// Convenience: returns Theta as a new vector (tests, tools). Same policy.
std::vector<float> computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                                ThetaReport* report = nullptr, std::vector<ThetaJointIssue>* issues = nullptr);

// The same with the gravity values after the joints' blocks when `rootGravity` (theta: 6 x joints + 3
// floats). The root's rotation is sanitised by the same policy; an issue with it names joint 0 and the
// slot after the last joint.
ThetaReport computeTheta(std::span<const uint32_t> inputJoints, bool rootGravity, std::span<const Quatf> localRotations,
                         std::span<float> theta, std::vector<ThetaJointIssue>* issues = nullptr);
std::vector<float> computeTheta(std::span<const uint32_t> inputJoints, bool rootGravity,
                                std::span<const Quatf> localRotations, ThetaReport* report = nullptr,
                                std::vector<ThetaJointIssue>* issues = nullptr);

}  // namespace swish::runtime
