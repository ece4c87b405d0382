#pragma once
// The run-time push-out (a step at the end of shaders/deform.glsl) and its CPU reference: each skinned
// garment vertex is kept outside its body anchor's ball (BodyAnchor in model/model.hpp, fitted at bake
// time by bake/training/body_anchor_fit.hpp: the largest ball inside the body touching it at the
// vertex's closest point), its clearance off the ball's surface.
//
// Per instance and vertex x (skinned, character space) with anchor (rest centre q = centre(), reach
// r = reach() = radius + clearance, joints j_i, weights w_i):
//   B = sum over i = 0..3 with w_i != 0 of w_i * M[j_i]           (elementwise, i ascending, from 0)
//   c = ((B.col0 * q.x + B.col1 * q.y) + B.col2 * q.z) + B.col3     (the skinned centre)
//   e = x - c;  s = (e.x e.x + e.y e.y) + e.z e.z
//   if kMinAnchorDistanceSq < s < r^2:  x = c + e * (r / sqrt(s))
// That is the garment's own linear blend skinning (runtime/reference_skinning.hpp) applied to the
// centre with the anchor's influences, then a radial push to the sphere of radius r: it never pulls a
// vertex in, and it is continuous in x (the move is 0 on the sphere), so a device whose rounding
// differs near the sphere differs by rounding only. A vertex without an anchor has r = 0 and stays, as
// does one whose anchor matrices are not finite (s is NaN) or that sits on the centre (no direction).
// A model with second anchors (BodyAnchors::second, format 1.4) then does the same for the vertex's
// second anchor, starting from where the first left it, and one with third (cover) anchors (format 1.5)
// for its third: up to three pushes in that order, each as above.
//
// Why per-vertex anchors and not a proxy of the whole body (capsules, formats 1.1 and 1.2): a vertex
// pushed out of the nearest of several overlapping shapes can land inside another, or inside the real
// body elsewhere (measured: it raised the deepest penetration and the error); an anchor is local,
// so a sleeve vertex anchored on the arm is never pushed out of the torso. The cost is a second
// blend of four skinning matrices per vertex and instance, and no per-frame CPU work.
#include <span>

#include "swish/model/model.hpp"

namespace swish::runtime {

// Below this squared distance (m^2, 1 micrometre) from the centre a vertex is not moved (no direction).
inline constexpr float kMinAnchorDistanceSq = 1e-12f;

// The anchor's ball centre skinned by `skinMatrices` (the formula above). Throws Error for a weighted
// joint without a matrix.
Vec3f skinAnchorCentre(const BodyAnchor& anchor, std::span<const Mat4f> skinMatrices);

// Where the push-out puts x for an anchor whose skinned centre is c (the formula above); x itself
// when it is not moved.
Vec3f pushedOutOfBall(const Vec3f& x, const Vec3f& c, float reach);

// Pushes `positions` (one instance, skinned, character space; one row per game-mesh vertex) out of
// their anchors' balls (each anchor set in order), in place. `skinMatrices`: that instance's, one per joint. Returns
// how many vertices moved. Throws Error when the anchors do not match the positions or name a joint without a matrix;
// empty anchors do nothing.
size_t referencePushOut(Points3f& positions, const BodyAnchors& anchors, std::span<const Mat4f> skinMatrices);

}  // namespace swish::runtime
