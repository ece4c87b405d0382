#pragma once
// Rotations: unit quaternions and the continuous 6D representation of Zhou et al. 2020.
//
// 6D convention (used by Theta everywhere): the first two COLUMNS of the rotation matrix, column 0
// then column 1: [R00, R10, R20, R01, R11, R21]. For the identity that is [1,0,0, 0,1,0].
#include <array>

#include "swish/core/types.hpp"

namespace swish {

using Rot6 = std::array<float, 6>;

// What sanitizeQuaternion did to its input.
enum class QuatStatus {
  Ok,            // finite and unit to within 1e-3 (normalised anyway, so downstream sees exact unit)
  Renormalised,  // finite, norm off by more than 1e-3 but at least 1e-6: divided by its norm
  Invalid,       // NaN/Inf component, or norm below 1e-6: replaced by the identity
};

struct SanitizedQuat {
  Quatf q;
  QuatStatus status;
};

// The documented policy for quaternions arriving from outside (animation files, host engines):
// normalise what can be normalised, replace what cannot by the identity, and say which happened so
// the caller can report it. Never silently.
SanitizedQuat sanitizeQuaternion(const Quatf& q);

Rot6 toRot6(const Quatf& q);  // q must be unit (sanitize first)
Rot6 toRot6(const Mat3f& r);
// Back to a rotation matrix by Gram-Schmidt on the two columns (defined for any non-degenerate input).
Mat3f rot6ToMatrix(const Rot6& r6);

// Shortest-arc spherical interpolation, t in [0,1].
Quatf slerpShortest(const Quatf& a, const Quatf& b, float t);

// Smoothstep-eased t for the slow A-pose -> target transitions of the bake (zero velocity at ends).
inline float easeInOut(float t) {
  t = t < 0.f ? 0.f : (t > 1.f ? 1.f : t);
  return t * t * t * (t * (t * 6.f - 15.f) + 10.f);  // quintic smootherstep
}

}  // namespace swish
