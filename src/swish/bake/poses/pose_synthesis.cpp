#include "swish/bake/poses/pose_synthesis.hpp"

#include <cmath>

#include "swish/bake/poses/pose_thinning.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

Quatf rotationBetween(const Quatf& a, const Quatf& b, float t) {
  Quatf r = a.conjugate() * b;                // a^-1 b, unit quaternions
  if (r.w() < 0.f) r.coeffs() = -r.coeffs();  // the shortest arc
  const Eigen::AngleAxisf arc(r.normalized());
  return (a * Quatf(Eigen::AngleAxisf(t * arc.angle(), arc.axis()))).normalized();
}

Pose poseOfSynthesized(const Skeleton& skeleton, const std::vector<AnimationClip>& clips, const SynthesizedPose& s) {
  Pose p = poseOfSample(skeleton, clips, s.base);
  for (const SynthesizedPose::Draw& d : s.draws) {
    if (d.joint >= skeleton.size())
      throw Error("synthesized pose: joint " + std::to_string(d.joint) + " of " + std::to_string(skeleton.size()));
    const Pose donor = poseOfSample(skeleton, clips, d.donor);
    p.local[d.joint] = rotationBetween(p.local[d.joint], donor.local[d.joint], d.t);
  }
  return p;
}

SynthesisResult synthesizePoses(const Skeleton& skeleton, const std::vector<AnimationClip>& clips,
                                const PoseSamples& samples, const std::vector<uint32_t>& kept,
                                const std::vector<uint32_t>& thetaJoints, const PoseSynthesisSettings& settings) {
  SynthesisResult out;
  if (!settings.enabled()) return out;
  if (samples.size() == 0) throw Error("part1.synthesis: no recorded samples to draw poses from");
  if (size_t(samples.dim) != 6 * thetaJoints.size())
    throw Error("part1.synthesis: the samples have " + std::to_string(samples.dim) + " values, Theta of " +
                std::to_string(thetaJoints.size()) + " joints has " + std::to_string(6 * thetaJoints.size()));
  if (!(settings.extend >= 0.f && settings.extend <= 1.f))
    throw Error("part1.synthesis.extend: must be in [0, 1], is " + std::to_string(settings.extend));
  std::vector<uint32_t> joints;
  for (const std::string& name : settings.joints) {
    const int j = skeleton.find(name);
    if (j < 0) throw Error("part1.synthesis.joints: joint '" + name + "' is not in the character's skeleton");
    joints.push_back(uint32_t(j));
  }

  // Candidates.
  const size_t count = settings.candidates > 0 ? settings.candidates : 8 * settings.poses;
  Rng rng(settings.seed);
  std::vector<SynthesizedPose> candidates(count);
  for (SynthesizedPose& c : candidates) {
    c.base = samples.origins[rng.below(samples.size())];
    for (uint32_t j : joints) {
      SynthesizedPose::Draw d;
      d.joint = j;
      d.donor = samples.origins[rng.below(samples.size())];
      d.t = float(rng.uniform(-double(settings.extend), 1.0 + double(settings.extend)));
      c.draws.push_back(d);
    }
  }

  // One pool: the kept recorded samples first (kept before the pass), then the candidates.
  PoseSamples pool;
  pool.dim = samples.dim;
  pool.values.reserve((kept.size() + count) * size_t(samples.dim));
  for (uint32_t k : kept) {
    if (k >= samples.size()) throw Error("part1.synthesis: kept sample " + std::to_string(k) + " out of range");
    pool.values.insert(pool.values.end(), samples.row(k), samples.row(k) + samples.dim);
  }
  for (const SynthesizedPose& c : candidates) {
    const Pose p = poseOfSynthesized(skeleton, clips, c);
    const std::vector<float> theta = runtime::computeTheta(thetaJoints, p.local);
    pool.values.insert(pool.values.end(), theta.begin(), theta.end());
  }
  pool.origins.resize(pool.size());  // the greedy pass reads values only

  ThinToCountOptions o;
  for (uint32_t i = 0; i < kept.size(); ++i) o.keepFirst.push_back(i);
  const ThinningResult thin = thinPosesToCount(pool, kept.size() + settings.poses, o);
  for (size_t i = kept.size(); i < thin.kept.size(); ++i) out.added.push_back(candidates[thin.kept[i] - kept.size()]);
  out.candidates = count;
  out.tolerance = thin.tolerance;
  out.passes = thin.passes;
  return out;
}

}  // namespace swish::bake
