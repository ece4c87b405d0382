#pragma once
// Skeleton and forward kinematics, in the glTF convention: a joint's local transform is
// T(rest translation) * R(local rotation), where the local rotation REPLACES the rest rotation (at the
// rest pose, local rotation == rest rotation). Parents come before children. The rest pose is the
// character's A-pose.
#include <string>
#include <string_view>
#include <vector>

#include "swish/core/types.hpp"

namespace swish {

struct Joint {
  std::string name;
  int parent = -1;      // index of the parent joint, -1 for a root
  RigidTransform rest;  // local rest transform relative to the parent
};

// A pose of a whole skeleton: one local rotation per joint (unit quaternions) plus the root joint's
// translation in character space (which replaces the root's rest translation).
struct Pose {
  std::vector<Quatf> local;
  Vec3f rootTranslation = Vec3f::Zero();
};

class Skeleton {
 public:
  std::vector<Joint> joints;
  std::vector<Mat4f> inverseBind;  // per joint: character space -> joint space at the bind (rest) pose

  size_t size() const { return joints.size(); }
  // Index of the joint with this name, or -1.
  int find(std::string_view name) const;
  // Throws Error naming `what` if parents are out of order, names repeat, or sizes disagree.
  void validate(const std::string& what = "skeleton") const;

  Pose restPose() const;
  // Global (character-space) joint transforms for a pose. pose.local.size() must equal size().
  std::vector<RigidTransform> globalTransforms(const Pose& pose) const;
  // Skinning matrices: global(pose) * inverseBind, one per joint.
  std::vector<Mat4f> skinningMatrices(const Pose& pose) const;
  // Sets inverseBind from the rest pose.
  void computeInverseBindFromRest();
};

// The joint's counterpart across the body's mid-plane: Left/Right swapped, and CMU's short L/R prefix
// (LHipJoint, RThumb: an upper-case letter follows); the name itself for a centre joint.
std::string mirroredJointName(const std::string& name);

}  // namespace swish
