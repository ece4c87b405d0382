#pragma once
// The run-time push-out (a step at the end of shaders/deform.glsl) and its CPU reference: garment
// vertices that the reconstruction put inside the model's body proxy (BodyProxy in model/model.hpp,
// capsules fitted inside the body at bake time) are moved out to the proxy's surface.
//
// Posing is done on the CPU, once per instance and capsule (a few dozen matrix products a frame): each
// capsule's ends go through its joint's skinning matrix, and the GPU reads the posed capsules as
// kPosedCapsuleFloats floats each: a.xyz, radius, d.xyz = b - a, invLenSq = 1 / |d|^2 (0 for a sphere).
// Then, per skinned vertex x and per capsule in the proxy's order:
//   w = x - a;  t = clamp(((w.x d.x + w.y d.y) + w.z d.z) * invLenSq, 0, 1);  q = a + d t;  e = x - q
//   s = (e.x e.x + e.y e.y) + e.z e.z
//   if kMinPushDistanceSq < s < r^2:  x = q + e * (r / sqrt(s))
// A vertex on a capsule's axis (s below kMinPushDistanceSq) has no outward direction and stays. The
// result is continuous in x (the push is 0 on the capsule surface), so a device whose rounding differs
// near the surface differs by rounding only.
//
// Why a proxy and not the body: the run time has no body mesh (a game's body is the host's), and a
// capsule test is a dozen flops: the step costs O(capsules) per vertex and instance, no memory but the
// posed capsules, which every thread of a dispatch reads alike.
#include <span>
#include <vector>

#include "swish/model/model.hpp"

namespace swish::runtime {

inline constexpr size_t kPosedCapsuleFloats = 8;
// Below this squared distance (m^2, 1 micrometre) from the axis a vertex is not moved (no direction).
inline constexpr float kMinPushDistanceSq = 1e-12f;

// The proxy posed by one instance's skinning matrices (one per joint): kPosedCapsuleFloats per capsule
// appended to `out`. Throws Error when a capsule's joint has no matrix.
void poseBodyProxy(const BodyProxy& proxy, std::span<const Mat4f> skinMatrices, std::vector<float>& out);

// Pushes `positions` (one instance, skinned, character space) out of the posed capsules, in place.
// Returns how many vertices moved.
size_t referencePushOut(Points3f& positions, std::span<const float> posedCapsules);

}  // namespace swish::runtime
