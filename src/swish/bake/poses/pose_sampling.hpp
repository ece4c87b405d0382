#pragma once
// Pose recording: every frame of the given clips, as several "characters" would play them in a game
// (each with its own clip order, start offset, playback speed and optional left/right mirroring),
// sampled at a fixed rate into Theta vectors (6D of the chosen joints' local rotations, in the order
// of the joint list; toRot6 in core/rotation.hpp): the same vector runtime::computeTheta makes of a
// pose for those joints. The greedy thinning (pose_thinning.hpp) reduces them.
#include <cstdint>
#include <string>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::bake {

// A dense cloud of Theta vectors, row-major: sample i is values[i*dim .. i*dim+dim).
struct PoseSamples {
  int dim = 0;
  std::vector<float> values;
  // Where each sample came from, so a kept sample can be turned back into a full-skeleton Pose.
  struct Origin {
    uint32_t character = 0;  // virtual character index
    uint32_t clip = 0;       // index into the clip list
    float frame = 0.f;       // fractional frame in that clip
    bool mirrored = false;
  };
  std::vector<Origin> origins;

  size_t size() const { return dim > 0 ? values.size() / size_t(dim) : 0; }
  const float* row(size_t i) const { return values.data() + i * size_t(dim); }
};

struct PoseSamplingOptions {
  std::vector<std::string> joints = defaultInputJointNames();
  // How many virtual characters play the clips, and for how long each, at which rate. The paper's
  // volume: 22 characters, 600 s, 60 fps. With one character, no mirroring and speed 1 and
  // sampleRate 0 ("every frame"), each clip frame is sampled exactly once.
  uint32_t characters = 1;
  double secondsPerCharacter = 0.0;  // 0: each character plays every clip once, in full
  double sampleRate = 0.0;           // samples per second; 0: the clips' own frame rate
  bool mirrorOddCharacters = true;   // characters 1, 3, 5... play mirrored (left <-> right)
  float speedJitter = 0.1f;          // characters > 0 play at 1 +- this (uniform)
  uint64_t seed = 1;
  // Per clip (empty: all 1), > 0: how densely the clip is sampled. Every clip once: weight w samples
  // it at w times the rate. A recording of given length: a clip is entered with probability
  // proportional to its weight. The thinning then works on the union (pose_thinning.hpp).
  std::vector<double> clipWeights;
};

// Samples the clips (already retargeted onto `skeleton`) into Theta vectors. Throws Error when a joint
// name is not in the skeleton, a clip is empty, or a clip's frames do not fit the skeleton.
PoseSamples samplePoses(const Skeleton& skeleton, const std::vector<AnimationClip>& clips,
                        const PoseSamplingOptions& options = {});

// The full-skeleton pose a sample stands for (same interpolation and mirroring as samplePoses).
Pose poseOfSample(const Skeleton& skeleton, const std::vector<AnimationClip>& clips, const PoseSamples::Origin& origin);

// Mirrors a pose across the character's YZ plane (x -> -x): swaps Left*/Right* (and L*/R* CMU
// prefixes such as LHipJoint/RHipJoint) joints and reflects each local rotation (w,x,y,z) ->
// (w,x,-y,-z). Valid for skeletons symmetric about x = 0 whose rest frames are mirror images (true of
// identity-rest A-pose skeletons such as the CMU-named ones here).
Pose mirrorPose(const Skeleton& skeleton, const Pose& pose);

}  // namespace swish::bake
