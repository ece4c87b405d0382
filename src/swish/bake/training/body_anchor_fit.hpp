#pragma once
// Fits the body anchors of the run-time push-out (BodyAnchors in model/model.hpp) to a character's
// body: for each garment (game-mesh) vertex at rest, the closest point on the body's triangles (the
// BodyCollider's grid search over the rest body, whose union-of-parts answer is the visible surface
// for a point outside it), with
//   - the body's outward normal there: the corners' area-weighted vertex normals (seam copies welded)
//     interpolated barycentrically and normalised, turned to agree with the collider's pseudo-normal
//     of the closest feature (which is outward for every closed part) where they disagree;
//   - the body's skin there: the three corners' weights interpolated barycentrically, the
//     kAnchorInfluences largest kept (ties: the lower joint) and renormalised;
//   - the radius of the largest ball inside that point's part of the body that touches the surface
//     there (bisection on the part's signed distance; a limb's own radius on a limb, a large ball on
//     a flat trunk, a small one in a crease).
//
// A vertex farther than maxDistance from the rest body gets no anchor. Why a bound: the ball stands
// for the body under the vertex, as seen from the vertex. A vertex that hangs free of the body (a hem
// below the waist, a loose cuff) has its closest body point at a steep angle and far off, and in
// motion it swings past where that point goes (the hem past the hip): a constraint there would push
// cloth where the simulation has it. 4 cm is well beyond where a tight garment sits on the body at
// rest (the default jersey: 26 mm at most, 17 mm median) and about a limb's radius.
#include <cstddef>

#include <nlohmann/json.hpp>

#include "swish/core/mesh.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct BodyAnchorFitSettings {
  float maxDistance = 0.04f;  // metres from the rest body; farther vertices get no anchor (see above)
  float margin = 0.002f;      // BodyAnchors::margin written into the result
  float maxRadius = 0.3f;     // metres: the largest ball tried (a trunk is not thicker)
  // Also the second anchors (BodyAnchors::second): for each anchored vertex, the closest point of
  // another body part within maxDistance, fitted the same way (a shoulder's jersey on the trunk gets
  // the upper arm, whose end rises through it when the arm hangs).
  bool secondAnchors = true;
  // Slide anchors (with poses given to fitBodyAnchors): cloth slides over the body (the jersey rides up
  // over the belly when the arms rise), and a ball touching the body where the vertex sat at rest then
  // lies under the skin the vertex has slid onto: the push-out, out of that ball, leaves it inside the
  // body (measured on the default model's first frame of CMU 01_01, arms out: 33 belly and chest
  // vertices up to 2.8 mm inside after the push-out, each 52-74 mm from its anchor's contact, its
  // ball's surface 16-30 mm under the skin there). A vertex with no second anchor then gets, as its
  // second, the ball at the rest-body point under it in the pose where its cloth touches the body (within
  // `slideContact`) and the first ball misses that skin most, on the same part, when it misses it by
  // `slideMinGap` or more. Every ball lies inside the body, so a second one pushes only a vertex
  // already inside the body (as the first).
  float slideContact = 0.01f;  // metres from the posed body
  float slideMinGap = 0.003f;  // metres
  size_t slidePoses = 400;     // at most this many of the poses given, evenly spread
  // Cover anchors (BodyAnchors::third, format 1.5; with poses): one slide slot holds one place the cloth
  // slides to, the pose of the largest miss (the T-pose's belly, rare and large), and leaves the frequent
  // ones (the skin of a bent elbow under its sleeve end, in every pose the arm bends). So each anchored
  // vertex also gets, as its third, the ball that covers most of what the first two sets still miss: over
  // the same poses, the posed skin under the cloth (within slideContact, on the first anchor's part) that
  // lies slideMinGap or more outside both balls is a miss, weighted by that gap; of up to
  // coverCandidates balls (under the largest miss and under misses spread evenly over the poses, taken back
  // to the rest body as the slide anchors are), the one whose posed ball reaches most of that weight (each
  // pose's skin within coverReach of its surface) is kept.
  bool coverAnchors = true;
  float coverReach = 0.003f;    // metres
  size_t coverCandidates = 16;  // at least 1
  // Each anchor's skin on the garment vertex's own joints (onGarmentJoints, below), as the last step:
  // the run time's push-out then needs no matrices beyond the ones the vertex's skinning fetches.
  bool garmentJoints = true;
};

// A pose to find the slide anchors in (see the settings): the body's skinning matrices and the
// garment there (character space, posed, one row per garment vertex), both in the anchors' skeleton.
struct BodyAnchorSlidePose {
  std::vector<Mat4f> skinMatrices;
  const Points3f* garment = nullptr;
};

struct BodyAnchorFit {
  BodyAnchors anchors;
  size_t anchored = 0;           // vertices with an anchor
  size_t secondAnchored = 0;     // vertices with a second anchor (on another part or a slide one; see the settings)
  size_t slideAnchored = 0;      // of them, slide anchors (on the vertex's own part, where it slid to)
  std::vector<uint8_t> isSlide;  // per garment vertex (or empty: none): 1 where its second anchor is a slide anchor
  size_t slidePoses = 0;         // poses searched for them
  float slideMedianMm = 0, slideMaxMm = 0;  // of the slide anchors: distance of their contact from the first's (rest)
  float slideGapMedianMm = 0;               // of the slide anchors: how far the first ball missed the skin there
  size_t coverAnchored = 0;                 // vertices with a third (cover) anchor
  size_t coverMisses = 0;   // (pose, vertex) pairs whose skin the first two sets miss by slideMinGap or more
  size_t coverCovered = 0;  // of them, those within coverReach of the vertex's cover ball
  size_t tooFar = 0;        // vertices beyond maxDistance (no anchor)
  // onGarmentJoints (settings.garmentJoints): anchors whose skin it changed, the influences it dropped
  // (their weights' mean and largest), and anchors left with none (removed).
  size_t garmentJointsChanged = 0, garmentJointsDropped = 0, garmentJointsRemoved = 0;
  float garmentJointsMeanDropped = 0, garmentJointsMaxDropped = 0;
  size_t insideAtRest = 0;    // anchored vertices inside the body at rest (the push-out moves them at rest)
  size_t withinMargin = 0;    // anchored vertices nearer their ball than the margin at rest (pushed at rest)
  size_t flippedNormals = 0;  // interpolated normals turned to agree with the pseudo-normal
  // Distance of the anchored vertices to their anchors at rest (mm): median, 95th percentile, largest.
  float medianMm = 0, p95Mm = 0, maxMm = 0;
  float maxDistanceMm = 0;                    // the bound used (settings.maxDistance)
  float radiusP10Mm = 0, radiusMedianMm = 0;  // of the anchors' balls
};

// `body` skinned to `skeleton` (rest positions, triangles, skin; validated, errors name the problem),
// `garment` the game mesh at rest (character space, as the body). Deterministic.
// `poses` (may be empty: no slide anchors): see BodyAnchorFitSettings::slideMinGap; errors name a pose whose
// sizes do not fit.
BodyAnchorFit fitBodyAnchors(const Mesh& body, const Skeleton& skeleton, const Mesh& garment,
                             const BodyAnchorFitSettings& settings = {},
                             const std::vector<BodyAnchorSlidePose>& poses = {});

// Puts every anchor's skin on its garment vertex's own joints: an anchor influence whose joint is not
// among the vertex's skin joints (`garmentSkin`, the game mesh's) is dropped and the rest renormalised,
// in rank order; an anchor with none left is removed. Why: the run time's deform fetches each of a
// vertex's joint matrices once per instance, the skinning's and the push-out's alike
// (gpu::DeformPass::anchorExtraJointsOf), and an anchor joint off the vertex's skin costs three more
// fetches per instance for the whole mesh. On the committed jersey's fit, 759 of its anchors'
// influences, 7 % of their weight on average, were off the vertex's joints (the garment's skin is
// transferred from the body's, so the body under a vertex mostly moves with its joints); dropping them
// left the pictures and the penetration measure the same (docs/baking.md). Fills the fit's
// garmentJoints* counters. Errors name a size mismatch.
void onGarmentJoints(BodyAnchorFit& fit, const SkinWeights& garmentSkin);

// Calibration against the source simulation. The ball stands for the body, but the bake's own
// simulated garment (the truth the network learns) lies inside it in places: cloth squeezed between an
// arm and the trunk that overlap in a pose, a hem over the thigh, a sleeve the transfer's smoothing
// draws into the arm. There, pushing the network's garment out to the ball moves it away from the
// truth; and the truth's depth follows the pose (where the network puts a vertex deep, the truth is
// mostly deep there too), so no per-vertex bound taken from the truth alone serves.
//
// So the calibration measures the push-out itself: on each calibration pose it has the network's garment
// (without the push-out) and the truth, and per anchor it takes the HIGHEST clearance, from the margin
// down in `step`s, at which pushing that vertex out on every calibration pose does not raise the sum of
// its distances to the truth over those poses. A clearance below every calibration pose's distance
// pushes nothing there and qualifies, so one is found unless the network put the vertex deeper than
// its ball's radius or kMaxAnchorDepth; such an anchor is dropped. The push-out then removes what it can
// without making any vertex worse on the calibration poses. Second anchors (BodyAnchors::second) are
// calibrated the same way after the first, on where the first anchor's push leaves each vertex, as the
// run time applies them, and the third (cover) anchors after the second.
struct BodyAnchorCalibrationSettings {
  float step = 0.001f;  // metres between the clearances tried
  // Metres of mean distance to the truth per calibration pose that pushing a vertex may add (0: none).
  float tolerance = 0.f;
  bool second = true;  // calibrate the second and third anchors too (false: they keep the margin)
};

struct BodyAnchorCalibrationPose {
  std::vector<Mat4f> skinMatrices;      // the pose's, one per joint
  const Points3f* truth = nullptr;      // the simulated garment, character space, posed
  const Points3f* predicted = nullptr;  // the network's garment there, without the push-out (the run time's)
};

struct BodyAnchorCalibration {
  size_t poses = 0;
  size_t lowered = 0;         // anchors whose clearance went below the margin
  size_t dropped = 0;         // anchors dropped (see above), second anchors included
  size_t secondDropped = 0;   // of them, second and third anchors
  float medianLoweredMm = 0;  // median clearance of the lowered anchors (mm, negative: inside the ball)
  // Over the calibration poses and every vertex: mean distance to the truth (mm) without and with the
  // calibrated push-out, and the share of (pose, vertex) pairs it moves.
  double meanMmWithout = 0, meanMmWith = 0, pushedShare = 0;
};

// Throws Error naming the problem for sizes that do not fit the anchors. Deterministic.
BodyAnchorCalibration calibrateBodyAnchors(BodyAnchors& anchors, const std::vector<BodyAnchorCalibrationPose>& poses,
                                           const BodyAnchorCalibrationSettings& settings = {});

// The fit's figures for the model's metadata ("body_anchors") and reports.
nlohmann::json toJson(const BodyAnchorFit& fit);
nlohmann::json toJson(const BodyAnchorCalibration& calibration);

}  // namespace swish::bake
