#pragma once
// Pose synthesis (part1.synthesis): poses between and around the recorded ones, for joints whose
// rotation the corpus varies between subjects but hardly within one.
//
// Why: a motion-capture corpus is a handful of performers, each fitted to a skeleton of their own. A
// joint such as the clavicle (LeftShoulder, RightShoulder) then holds one rotation per subject for
// every frame of every clip: in the default corpus 17 to 27 degrees from the character's rest,
// constant to within a degree per subject, five values in all. The cloth follows it (the arm root
// moves with it; re-simulating a held-out subject's pose with another subject's clavicles moves the
// shape 8 to 50 mm), but a network that saw five values learns a subject code, not the clavicle: on a
// subject whose clavicles lie between or beyond them it is off by the same several millimetres in every
// frame (docs/baking.md, "Poses between the subjects"). Synthesis draws candidate poses whose named
// joints take rotations between and a little beyond those of two recorded samples, and the thinning
// keeps those that cover Theta space the recorded poses leave empty.
//
// Each candidate: a random recorded sample (the base), and for each named joint an independent
// random recorded sample (the donor) and t uniform in [-extend, 1 + extend]; the joint's local rotation
// becomes base * (base^-1 donor)^t, the rotation from the base's towards the donor's by t of the
// angle between them (past it for t > 1, away from it for t < 0). The candidates are thinned against
// the kept recorded poses with the same greedy pass (pose_thinning.hpp) to `poses` more: they come
// after the recorded poses, so a recipe that adds synthesis keeps its recorded poses' ids and their
// simulations. Deterministic for a seed.
//
// Measured (session 25): 926 synthesized clavicle poses added to the default corpus bake did not lower the
// held-out subjects' error (7.60 against 7.53 mm; subject 8's per-frame-constant share 6.69 against 6.56),
// so the default recipe does not use it; docs/baking.md has the table and the leads left.
#include <cstdint>
#include <string>
#include <vector>

#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

struct PoseSynthesisSettings {
  std::vector<std::string> joints;  // the joints redrawn; empty: no synthesis
  size_t poses = 0;                 // synthesized poses to add (the thinning's target, within 2 %)
  size_t candidates = 0;            // candidates drawn before thinning; 0: 8 x poses
  float extend = 0.25f;             // t in [-extend, 1 + extend]
  uint64_t seed = 1;
  bool enabled() const { return !joints.empty() && poses > 0; }
};

struct SynthesizedPose {
  PoseSamples::Origin base;
  struct Draw {
    uint32_t joint = 0;  // skeleton index
    PoseSamples::Origin donor;
    float t = 0.f;
  };
  std::vector<Draw> draws;  // one per named joint, in the settings' order
};

// The full-skeleton pose of a synthesized sample (the base as poseOfSample gives it, then each draw).
Pose poseOfSynthesized(const Skeleton& skeleton, const std::vector<AnimationClip>& clips, const SynthesizedPose& s);

// `b` moved from `a` by t of the shortest arc between them; any t (t outside [0, 1] extrapolates).
Quatf rotationBetween(const Quatf& a, const Quatf& b, float t);

struct SynthesisResult {
  std::vector<SynthesizedPose> added;  // in the thinning's order
  size_t candidates = 0;
  float tolerance = 0.f;  // the thinning's, against the kept poses and each other
  int passes = 0;
};

// Draws the candidates from `samples` (their origins; the clips as samplePoses read them) and thins
// them against the recorded samples `kept` (indices into `samples`) in the Theta of `thetaJoints`
// (skeleton indices, the order of samples.dim / 6). Throws Error naming part1.synthesis for a joint
// that is not in the skeleton, or for no samples to draw from.
SynthesisResult synthesizePoses(const Skeleton& skeleton, const std::vector<AnimationClip>& clips,
                                const PoseSamples& samples, const std::vector<uint32_t>& kept,
                                const std::vector<uint32_t>& thetaJoints, const PoseSynthesisSettings& settings);

}  // namespace swish::bake
