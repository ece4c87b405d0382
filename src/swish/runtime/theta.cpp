#include "swish/runtime/theta.hpp"

#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

ThetaReport computeTheta(std::span<const uint32_t> inputJoints, bool rootGravity, std::span<const Quatf> localRotations,
                         std::span<float> theta, std::vector<ThetaJointIssue>* issues) {
  if (theta.size() != thetaSize(inputJoints.size(), rootGravity)) {
    const std::string gravity = rootGravity ? " + 3 gravity values" : "";
    throw Error("theta: output holds " + std::to_string(theta.size()) + " floats, expected 6 x " +
                std::to_string(inputJoints.size()) + " input joints" + gravity);
  }
  ThetaReport report;
  for (size_t slot = 0; slot < inputJoints.size(); ++slot) {
    const uint32_t joint = inputJoints[slot];
    if (joint >= localRotations.size())
      throw Error("theta: input joint " + std::to_string(slot) + " is skeleton joint " + std::to_string(joint) +
                  " but the pose has only " + std::to_string(localRotations.size()) + " rotations");
    const SanitizedQuat s = sanitizeQuaternion(localRotations[joint]);
    if (s.status != QuatStatus::Ok) {
      (s.status == QuatStatus::Invalid ? report.invalid : report.renormalised) += 1;
      if (issues) issues->push_back({joint, uint32_t(slot), s.status});
    }
    const Rot6 r = toRot6(s.q);
    for (int k = 0; k < 6; ++k) theta[6 * slot + k] = r[k];
  }
  if (rootGravity) {
    if (localRotations.empty())
      throw Error("theta: the pose has no rotations, so no root joint for the gravity values");
    const SanitizedQuat s = sanitizeQuaternion(localRotations[0]);
    if (s.status != QuatStatus::Ok) {
      (s.status == QuatStatus::Invalid ? report.invalid : report.renormalised) += 1;
      if (issues) issues->push_back({0u, uint32_t(inputJoints.size()), s.status});
    }
    const Vec3f g = s.q.conjugate() * Vec3f(0.f, -1.f, 0.f);
    for (int k = 0; k < 3; ++k) theta[6 * inputJoints.size() + size_t(k)] = g[k];
  }
  return report;
}

ThetaReport computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                         std::span<float> theta, std::vector<ThetaJointIssue>* issues) {
  return computeTheta(inputJoints, false, localRotations, theta, issues);
}

std::vector<float> computeTheta(std::span<const uint32_t> inputJoints, bool rootGravity,
                                std::span<const Quatf> localRotations, ThetaReport* report,
                                std::vector<ThetaJointIssue>* issues) {
  std::vector<float> theta(thetaSize(inputJoints.size(), rootGravity));
  const ThetaReport r = computeTheta(inputJoints, rootGravity, localRotations, std::span<float>(theta), issues);
  if (report) *report = r;
  return theta;
}

std::vector<float> computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                                ThetaReport* report, std::vector<ThetaJointIssue>* issues) {
  return computeTheta(inputJoints, false, localRotations, report, issues);
}

}  // namespace swish::runtime
