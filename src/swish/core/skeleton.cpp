#include "swish/core/skeleton.hpp"

#include <cctype>
#include <unordered_set>

#include "swish/core/error.hpp"

namespace swish {

int Skeleton::find(std::string_view name) const {
  for (size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == name) return int(i);
  return -1;
}

void Skeleton::validate(const std::string& what) const {
  if (joints.empty()) throw Error(what + ": skeleton has no joints");
  std::unordered_set<std::string> names;
  for (size_t i = 0; i < joints.size(); ++i) {
    const Joint& j = joints[i];
    if (j.parent >= int(i) || j.parent < -1)
      throw Error(what + ": joint '" + j.name + "' (index " + std::to_string(i) + ") has parent index " +
                  std::to_string(j.parent) + ", parents must come first");
    if (!names.insert(j.name).second) throw Error(what + ": joint name '" + j.name + "' repeats");
    if (!j.rest.translation.allFinite() || !j.rest.rotation.coeffs().allFinite())
      throw Error(what + ": joint '" + j.name + "' has a non-finite rest transform");
  }
  if (!inverseBind.empty() && inverseBind.size() != joints.size())
    throw Error(what + ": " + std::to_string(inverseBind.size()) + " inverse bind matrices for " +
                std::to_string(joints.size()) + " joints");
  for (size_t i = 0; i < inverseBind.size(); ++i)
    if (!inverseBind[i].allFinite())
      throw Error(what + ": inverse bind matrix of joint '" + joints[i].name + "' is not finite");
}

Pose Skeleton::restPose() const {
  Pose p;
  p.local.reserve(joints.size());
  for (const Joint& j : joints) p.local.push_back(j.rest.rotation);
  p.rootTranslation = joints.empty() ? Vec3f::Zero() : joints[0].rest.translation;
  return p;
}

std::vector<RigidTransform> Skeleton::globalTransforms(const Pose& pose) const {
  if (pose.local.size() != joints.size())
    throw Error("pose has " + std::to_string(pose.local.size()) + " rotations for a skeleton of " +
                std::to_string(joints.size()) + " joints");
  std::vector<RigidTransform> g(joints.size());
  for (size_t i = 0; i < joints.size(); ++i) {
    const Joint& j = joints[i];
    RigidTransform local{pose.local[i], j.parent < 0 ? pose.rootTranslation : j.rest.translation};
    g[i] = j.parent < 0 ? local : g[j.parent] * local;
  }
  return g;
}

std::vector<Mat4f> Skeleton::skinningMatrices(const Pose& pose) const {
  auto g = globalTransforms(pose);
  std::vector<Mat4f> m(g.size());
  for (size_t i = 0; i < g.size(); ++i)
    m[i] = g[i].matrix() * (inverseBind.empty() ? Mat4f::Identity() : inverseBind[i]);
  return m;
}

void Skeleton::computeInverseBindFromRest() {
  auto g = globalTransforms(restPose());
  inverseBind.resize(g.size());
  for (size_t i = 0; i < g.size(); ++i) inverseBind[i] = g[i].inverse().matrix();
}

std::string mirroredJointName(const std::string& name) {
  if (name.rfind("Left", 0) == 0) return "Right" + name.substr(4);
  if (name.rfind("Right", 0) == 0) return "Left" + name.substr(5);
  if (name.size() > 1 && (name[0] == 'L' || name[0] == 'R') && std::isupper(static_cast<unsigned char>(name[1])))
    return std::string(1, name[0] == 'L' ? 'R' : 'L') + name.substr(1);
  return name;
}

}  // namespace swish
