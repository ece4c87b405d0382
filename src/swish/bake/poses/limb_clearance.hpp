#pragma once
// Limb clearance: keeps a pose's limbs out of the trunk before the garment is simulated on it.
//
// A body made of separate closed parts (the embedded mannequin's torso, head, arm and leg tubes) and
// driven by motion capture of a real person intersects itself: in the CMU clips the upper arms hang
// straight down, and the mannequin's arm tubes then pass 4-7 cm into its torso. Cloth cannot be
// outside both: a sleeve around an arm that is inside the torso is necessarily inside the body, and
// the solver tears it trying. So before simulating, each limb that has moved into the trunk is
// rotated about its root joint, away from the trunk, by the smallest whole number of degrees that
// leaves a clearance, just as datasets of simulated clothing filter or correct self-intersecting
// body poses. The bake simulates the corrected pose and stores the recorded one (part1_dataset.cpp).
//
// Only where the garment is: a limb counts as inside the trunk where the trunk's surface nearest it lies
// within garmentReach of the garment at rest. Cloth cannot be pinched where there is none, and a
// limb turned out for nothing moves the garment's simulated shape away from the recorded pose's (the
// thighs of the embedded mannequin touch its crotch, 7 cm below the jersey's hem, in most strides).
//
// Parts are the body's connected components; the trunk is the one with the most triangles. A limb's
// root joint is the shallowest joint carrying a tenth of its skin weight. Only limb vertices that lie
// outside the trunk in the rest pose and farther than rootRadius from the root joint are checked:
// the root of a tube starts inside the trunk by construction. A body that is one connected mesh has
// no parts of its own: its limbs are regions of its skin instead (below). A trunk that is not a closed
// surface has no inside; the limbs of such a body are left unchanged (skipped() says why).
//
// Limbs of a body that is ONE surface (a glTF character: the shared T-shirt's MakeHuman body). Its arms
// hang against its sides in a walk just as the mannequin's tubes pass into its torso, and a sleeve
// pinched there explodes the solve (4 of 30 thinned poses of unseen CMU subjects on the shared T-shirt,
// none with this step; docs/baking.md). So each limb is the skin region of a limb joint (named, as the importer
// compares names, ...LeftArm, ...RightArm, ...LeftUpLeg or ...RightUpLeg: every vertex whose strongest joint is that
// joint or below it), its root that joint, and the trunk is the rest of the body (the triangles with no corner in a
// limb region): an open surface whose sign is trusted away from its openings, so the trunk triangles within seamBorder
// of a limb region at rest (the armpit's and the groin's seams) are never kept clear, and limb vertices are checked as
// a part's are (beyond rootRadius from the root joint, outside the trunk at rest). Then the same turn as a part's. Off
// with oneSurfaceLimbs.
//
// Head clearance. A body that is ONE closed surface (a glTF character) has no limb parts, but its head
// can still pass into its own chest: a clip that bows the head further than the body's skinning
// allows puts the skinned chin centimetres inside the chest, and the collar between them has nowhere
// to be (the shared T-shirt's runaway at the neckline, docs/baking.md). So for such a body the head
// (vertices whose dominant skin joint is the joint named "Head", or ending in "Head", or below it;
// names compared as the importer compares them, io::normaliseJointName) is
// checked against the rest of the body (the other triangles, posed with it): a pose that puts a head
// vertex inside it by more than the tolerance has its neck chain (that joint and the ancestors named
// "...Neck...") turned back towards rest, every joint by the same smallest whole percentage of the
// way (slerp) that leaves no head vertex inside. Head vertices within headBorder of the rest of the
// body at rest (under the jaw, the neck seam) are not checked: skinning creases them into the neck in
// ordinary bends. A body of separate parts never gets this step: its head is a part that limb
// clearance already keeps out of the trunk (the embedded mannequin's is).
#include <optional>
#include <string>
#include <vector>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

struct LimbClearanceSettings {
  float clearance = 0.015f;  // m between a limb and the trunk: room for two layers of cloth
  float rootRadius = 0.10f;  // m: limb vertices this close to their root joint are not checked
  float maxDegrees = 60.f;   // the largest correction along the push (twice it in the turn search); a limb
                             // still inside after it is reported
  // m: only the trunk surface within this distance of the garment at rest is kept clear, where a limb
  // can pinch the cloth (the hem can ride up this far). A thigh against the crotch, below a jersey's
  // hem, is left as recorded. 0, or a character without a garment: the whole trunk.
  float garmentReach = 0.03f;
  float headBorder =
      0.03f;  // m: one-surface bodies' head vertices this close to the rest of the body at rest are not checked
  // Neck range (degrees; 0: none): where the neck chain's joints (the head joint and its "...Neck..."
  // ancestors) together turn further than this from rest, every one of them is turned back towards
  // rest by the same share of the way (slerp) until they turn this far. Why: a neck bowed or thrown
  // back beyond what a neck does (CMU rolls and retargeting, up to 88 degrees in each of Neck1 and
  // Head) sweeps the head's neck through the collar the garment's top band holds, and the solve
  // tears it there: 35 of the 44 poses the committed default bake lost to explosions turn the chain
  // by 90 degrees or more; at 90, 26 of the 44 are kept instead of 9 (docs/baking.md). The network
  // reads no neck joint, so what the neck does beyond this only adds shapes it cannot explain. Part of
  // the limb clearance: a bake without it (limb_clearance 0) leaves the neck as recorded too.
  float neckRangeDegrees = 90.f;
  // Whether a body that is one surface has its limbs (skin regions) kept out of its trunk (above).
  // Recipes: part1.simulation.limb_one_surface (settings recorded before it: false, so that models
  // baked before keep their truth).
  bool oneSurfaceLimbs = true;
  // Where the turn along the trunk's push does not clear a limb within maxDegrees (a limb deep in the
  // trunk: an arm aimed through the chest stays 4.5-6.7 cm inside after 60 degrees, and the cloth pinched
  // there explodes on every attempt), the smallest turn that clears it in any of 8 directions around
  // the limb, up to twice maxDegrees. A limb the push's turn clears is turned exactly as without it.
  // Recipes: part1.simulation.limb_turn_search (settings recorded before it: false).
  bool turnSearch = true;
  float seamBorder = 0.03f;  // m: one-surface trunk triangles this close to a limb region at rest are not kept clear
};

struct LimbCorrection {
  std::string joint;        // the root joint that was rotated
  float degrees = 0.f;      // by how much
  float depthBefore = 0.f;  // m: how far the limb was inside the clearance before
  float depthAfter = 0.f;   // after (0 when cleared)
  // Head clearance only (joint: the head joint): the fraction of the way back to rest the neck chain
  // was turned (0.2: 20 %); `degrees` is then how far that turned the head joint in its chain's frame.
  float towardsRest = 0.f;
  // The neck range (joint: the head joint; `degrees` taken off the chain's turn from rest), not a limb
  // turned out of the trunk.
  bool neckRange = false;
  // Head clearance (a one-surface body's head out of its chest), not a limb turned out of the trunk.
  bool head = false;
};

class LimbClearance {
 public:
  // Throws Error on a body without skin weights or settings out of range.
  LimbClearance(const Character& character, LimbClearanceSettings settings = {});

  // Rotates limbs of `pose` out of the trunk in place; returns what it changed (empty: nothing).
  // Deterministic; non-finite poses are left alone for the solver to reject.
  std::vector<LimbCorrection> apply(Pose& pose) const;

  size_t limbCount() const { return limbs_.size(); }
  // Trunk triangles kept clear (within garmentReach of the garment), of how many.
  size_t guardedTriangles() const;
  size_t trunkTriangles() const { return guarded_.size(); }
  // Why no limb is checked (empty when some are).
  const std::string& skipped() const { return skipped_; }
  // Whether the limbs are skin regions of a body that is one surface (above), not parts of their own.
  bool limbsAreRegions() const { return limbRegions_; }
  // Whether the head of a one-surface body is checked (see above), and how many of its vertices.
  bool checksHead() const { return head_.has_value(); }
  size_t headVertexCount() const { return head_ ? head_->vertices.size() : 0; }

 private:
  struct Limb {
    int rootJoint = -1;
    std::vector<uint32_t> vertices;   // checked vertices
    std::vector<float> restDistance;  // their signed distance to the trunk at rest
  };
  Skeleton skeleton_;
  Mesh body_;
  std::optional<BodyCollider> trunk_;  // the trunk alone, unposed: copied and posed per pose
  std::vector<char> guarded_;          // per trunk triangle (trunk_'s numbering): near the garment at rest
  LimbClearanceSettings settings_;
  std::vector<Limb> limbs_;
  std::string skipped_;
  bool limbRegions_ = false;
  // A body that is one surface: its limbs as skin regions and the rest as the trunk (above).
  void setUpLimbRegions(const Character& character);
  // The limbs (parts or regions) against the trunk, in place; p: `pose` with its root at rest.
  void applyLimbs(Pose& pose, Pose& p, std::vector<LimbCorrection>& out) const;
  // Appends a reason to skipped_.
  void skip(const std::string& why);
  // Keeps `limb` (its root set) with its checked vertices among `vertices`: farther than rootRadius from
  // the root joint's head and outside the rest-posed `trunk`, with their distance to it; a limb with none
  // is dropped. Shared by parts and skin regions.
  void addLimb(Limb limb, const std::vector<uint32_t>& vertices, const BodyCollider& trunk,
               const std::vector<RigidTransform>& restGlobal);

  struct Head {
    std::vector<uint32_t> vertices;     // checked head vertices (the joints turned back: neckChain_)
    std::optional<BodyCollider> rest;   // the body without the head's triangles, unposed
    std::optional<BodyCollider> whole;  // the whole closed body, unposed: its winding number confirms inside
    int wholePart = 0;
  };
  std::optional<Head> head_;
  // The head joint and its neck ancestors (empty: no joint named "Head"): what the neck range limits and
  // the head step turns back to rest.
  std::vector<int> neckChain_;
  void setUpHead();
  // The neck chain within settings_.neckRangeDegrees (see the settings); what it changed, if anything.
  std::optional<LimbCorrection> limitNeck(Pose& pose) const;
  // `p`: `pose` checked and with its root at rest (as apply measures it).
  std::optional<LimbCorrection> applyHead(Pose& pose, Pose p) const;
};

}  // namespace swish::bake
