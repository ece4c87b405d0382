#pragma once
// Distillation (train.distill): a smooth teacher, kernel ridge regression on the training poses
// (kernel_ridge.hpp), labels poses made between and around them, and the MLP learns from those labels
// as well as from the simulated ones. The network alone fits its few thousand training poses closely and
// is free to do anything between them; the teacher's labels there say what a smooth interpolant of the
// simulations says, at no simulation's cost.
//
// The synthetic poses change the network's input joints only (Theta reads nothing else):
//   - blends: a training pose moved towards one of its nearest training poses (in standardised Theta)
//     by t ~ U(0, 1) of the shortest arc, joint by joint;
//   - mixes: a training pose with each input joint, with probability `swapProbability`, taken from
//     another training pose drawn at random: combinations of joints the corpus did not record together,
//     as another subject's motion has.
#include <cstdint>
#include <span>
#include <vector>

#include "swish/bake/training/kernel_ridge.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/core/types.hpp"

namespace swish::bake {

struct DistillSettings {
  size_t poses = 0;               // synthetic poses (0: no distillation)
  double mixShare = 0.5;          // of them, the share made by mixing joints; the rest are blends
  double swapProbability = 0.25;  // per input joint of a mix
  int neighbours = 8;             // a blend's partner is one of this many nearest training poses
  uint64_t seed = 1;
  KernelRidgeOptions teacher;  // its output weights are the MLP's loss weights
};

struct DistilledSamples {
  MatXf theta;   // D x poses: the synthetic poses' network inputs
  MatXf lambda;  // M x poses: the teacher's outputs for them
  KernelRidgeFit teacher;
  size_t blends = 0, mixes = 0;
};

// poses: the training poses (local rotations of the whole skeleton); theta/lambda: their network inputs and
// targets, column i for poses[i]. Throws Error for mismatched sizes or settings out of range.
DistilledSamples distilledSamples(std::span<const Pose* const> poses, std::span<const uint32_t> inputJoints,
                                  bool rootGravity, const MatXf& theta, const MatXf& lambda,
                                  const DistillSettings& settings);

}  // namespace swish::bake
