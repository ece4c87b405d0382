#include "swish/runtime/theta.hpp"

#include <string>

#include "swish/core/error.hpp"

namespace swish::runtime {

ThetaReport computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                         std::span<float> theta, std::vector<ThetaJointIssue>* issues) {
  if (theta.size() != 6 * inputJoints.size())
    throw Error("theta: output holds " + std::to_string(theta.size()) + " floats, expected 6 x " +
                std::to_string(inputJoints.size()) + " input joints");
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
  return report;
}

std::vector<float> computeTheta(std::span<const uint32_t> inputJoints, std::span<const Quatf> localRotations,
                                ThetaReport* report, std::vector<ThetaJointIssue>* issues) {
  std::vector<float> theta(6 * inputJoints.size());
  const ThetaReport r = computeTheta(inputJoints, localRotations, std::span<float>(theta), issues);
  if (report) *report = r;
  return theta;
}

}  // namespace swish::runtime
