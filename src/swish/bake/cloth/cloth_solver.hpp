#pragma once
// The quasi-static garment solver of the bake (paper 2.2: "a slow 1 s transition from the A-pose to
// the target pose, keep the final frame"). XPBD with small substeps (Macklin et al. 2016, 2019):
// stretch, shear and bending constraints, the skinned body as a collider with thickness and Coulomb
// friction, gravity, damping, and the garment's top band softly attached to its skinned position.
//
// Following the body: at every frame the cloth is carried by the change of its own skinning, so a fast
// limb drags its sleeve along instead of tunnelling through it; the solver then corrects what skinning
// gets wrong (stretch, squash, penetration, drape). How it is carried is ClothCarry below.
//
// Coordinates: the solve runs relative to the garment's rest centre (huge character coordinates lose
// no precision inside the solve) and ignores the pose's root translation (the shape is a function of
// the joint rotations alone). Results are in character space with the root at its rest position.
#include <functional>
#include <string>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/cloth/cloth_constraints.hpp"
#include "swish/bake/cloth/cloth_material.hpp"
#include "swish/bake/cloth/constraint_schedule.hpp"
#include "swish/bake/cloth/simulation_mesh.hpp"
#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

// How the cloth follows the body from one frame to the next, before the frame's solve.
enum class ClothCarry {
  // Each vertex moved by its own skinning change B_new * B_old^-1: the cloth's offset from the vertex's
  // skinned place is turned with its blend. Where blends of very different rotations meet (an arm
  // raised overhead with its collar bone: the shoulder's cloth lies on the torso but is skinned partly
  // to the arm) neighbours turn their offsets differently, and every frame's solve starts from a
  // sheared cloth (docs/baking.md, "The carry").
  Skinning,
  // Each vertex moved by the displacement of its skinned rest position (B_new - B_old applied to its
  // rest position): the offset keeps its direction. Measured on the default bake's poses that
  // explode with Skinning: 11 of 16 simulate; on ordinary poses it is less converged (12.7 against
  // 9.7 mm mean on 16 poses), so it is not the default (docs/baking.md, "The carry").
  Translation,
  // Each vertex moved by the change of its dual-quaternion blend of the joints' transforms (Kavan et
  // al. 2007): rigid per vertex, so where linear blends collapse (an upper arm twisted far about its
  // bone: the sleeve's blends of the shoulder and the arm shrink to a fifth of their volume) the cloth
  // is turned with the arm instead of being drawn into it. Measured on the default bake's 11 lost
  // poses: it keeps one of them (pose 717) that both other carries lose. Only the carry: the game
  // mesh is still skinned linearly, by the run time as by the transfer.
  DualQuaternion,
};
// "skinning" | "translation" | "dual_quaternion": the names recipes and reports use.
const char* clothCarryName(ClothCarry carry);

// How a sweep runs its stretch, shear and bending blocks. All three give bitwise the same answer
// (constraint_schedule.hpp), so the choice is not part of the fingerprint; it is there for benchmarks
// and the tests that check the equality.
enum class SweepKernel {
  Sequential,  // the constraints one after another, in the order they were built
  Levels,      // in dependency levels, one at a time (the scalar twin of Vector)
  Vector,      // in dependency levels, eight at a time where the processor has AVX2 (the default)
};

struct ClothSimSettings {
  ClothMaterial material = clothMaterialPreset("jersey");
  float thickness = 0.004f;       // m: how far the cloth keeps off the body surface
  float contactMargin = 0.02f;    // m: vertices this close beyond the thickness get a contact plane
  float transitionSeconds = 1.f;  // A-pose -> target, eased
  float settleSeconds = 0.5f;     // at the target pose before the frame is kept
  float frameRate = 30.f;         // body poses (and contact planes) per second
  // Per frame, and constraint sweeps per substep. On the shared T-shirt at ~12k vertices 8 x 1 left
  // the rest pose 46% stretched under gravity (one Gauss-Seidel sweep per substep cannot carry the
  // weight up ~100 rows of edges); 12 x 2 leaves 20% (99th percentile 8.5%) for ~2x the time.
  // 24 x 1 does better still (15%) but makes the stiff preset oscillate (30% on the capsule test,
  // not understood yet), so the default stays at 12 x 2.
  int substeps = 12;
  int iterations = 2;
  Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);
  float attachTopFraction = 0.08f;  // top band of the garment (fraction of its rest height) attached
  float attachSag = 0.005f;         // m: how far the attached band would sag holding the whole garment
  float tetherSlack = 0.01f;        // tethers let a vertex stretch this much beyond its rest geodesic
  // Outcome bounds.
  float convergedSpeed = 0.05f;   // m/s: the fastest vertex in the last frame, to count as settled
  float convergedStrain = 0.25f;  // worst edge strain to count as converged
  float failPenetration = 0.01f;  // m inside the thick surface: the pose fails beyond this
  // The solve has exploded when more than failShare of the edges are stretched beyond failStrain
  // (relative to the edge's rest length, or half the median one if longer), or any edge beyond five
  // times that. A blow-up stretches edges everywhere; a few tens of edges over 100% on the shoulder
  // caps of a mannequin whose skinning squeezes them (0.05-0.2% of the edges, measured on the
  // default character) is a local residual, recorded in maxConstraintViolation and `converged`.
  float failStrain = 1.0f;
  float failShare = 0.01f;
  // The end condition: after the transition and the settle, frames at the goal pose until the
  // equilibrium residual (SimResiduals::equilibriumResidual: the unbalanced share of gravity's load)
  // is at most equilibriumTolerance, for at most equilibriumSeconds of simulated time, with
  // equilibriumIterations sweeps per substep (0: `iterations`). Chosen by measurement (default
  // jersey, 4 poses of unseen CMU clips, docs/baking.md): 10 sweeps for 0.5 s halve the distance to
  // the shape at twice the substeps (21.8 -> 9.7 mm mean); 2 sweeps for up to 1 s change nothing.
  float equilibriumTolerance = 0.01f;
  float equilibriumSeconds = 0.5f;
  int equilibriumIterations = 10;
  // Substeps per frame of the end phase (0: `substeps`). The stiff regime (docs/baking.md, "The stiff
  // regime") leaves XPBD's stretch to the sweeps and the substeps; the same sweeps spread over more
  // substeps (60 x 2 instead of 12 x 10) end at one stretch whatever the path's substeps. Measured on
  // the jersey: the stretch converges, the shape does not (the path's folds; docs/baking.md, "The end
  // phase on substeps of its own"), so off. Hashed into the fingerprint only when set, so that bakes
  // without it keep their cached poses.
  int equilibriumSubsteps = 0;
  // The static solve (static_solve.hpp), instead of the equilibrium phase: from the path's end, Newton
  // steps on the garment's energy at the goal pose until the residual (the same unbalanced share of
  // gravity's load, from the forces rather than the motion) is at most staticTolerance or
  // staticIterations steps are spent. Frictionless: the shape is the pose's, not the path's speed.
  bool staticSolve = false;
  float staticTolerance = 0.01f;
  int staticIterations = 40;
  // Every vertex closer to the body than the thickness at the end is moved out along the body's
  // normal (repeated where that moves it into another part).
  bool finalProjection = true;
  // A failed pose is simulated again up to `retries` times, each with twice the substeps and twice
  // the transition of the one before (the equilibrium phase at the base settings), before it is
  // left out.
  int retries = 1;
  ClothCarry carry = ClothCarry::Skinning;
  SweepKernel sweepKernel = SweepKernel::Vector;
  // The carries each retry tries in turn until one simulates (the first attempt uses `carry`). Measured
  // on the default bake's 3929 poses: the skinning carry then the translation carry keeps every pose
  // the skinning retry keeps, with the same shape, and 13 of the 24 it loses (docs/baking.md, "The carry").
  std::vector<ClothCarry> retryCarries = {ClothCarry::Skinning, ClothCarry::Translation};
  // After the retries (when retries >= 1), four attempts along safer paths before the pose is left
  // out: the transition with the limbs kept out of the trunk at every frame (the solver's path
  // clearance, given by the bake: limb_clearance.hpp applied to each frame's pose, not only the
  // target's) at the base speed and at half of it, both with the skinning carry, then the base path
  // with the dual-quaternion carry, then the cleared path at half speed with the translation carry. Why: a transition
  // that slerps each joint from the A-pose swings an arm through the trunk on its way to a target in front of or behind
  // the body, and the cloth caught between them explodes whatever the substeps; a far twist collapses the linear blends
  // the carry follows. Measured on the 11 poses the session-32 default bake lost in its simulation (docs/baking.md,
  // "Safer paths"): the cleared path keeps 4 (3 at the base speed, 1 at half), the dual-quaternion carry 1.
  // A pose that simulates before them is simulated as before. Recipes: part1.simulation.safer_path_retries (settings
  // recorded before it: false).
  bool saferPathRetries = true;
  // The retries of bakes from before retryCarries was a setting: the skinning carry alone. Fingerprints,
  // dataset settings and descriptions name retryCarries only when it differs from that.
  bool skinningRetriesOnly() const { return retryCarries == std::vector<ClothCarry>{ClothCarry::Skinning}; }

  // Throws Error naming the field that is out of range.
  void validate() const;
};

// One pose's outcome. When !ok, `failure` says why and `positions` is empty: never kept.
struct PoseSimulation {
  bool ok = false;
  std::string failure;
  int attempts = 1;          // 2 or more: the first attempt failed and the pose was retried
  std::string firstFailure;  // why the first attempt failed, when attempts > 1
  bool retryable = true;     // false for bad input (a failure no other setting can help)
  Points3f positions;        // simulation-mesh vertices, character space (root translation ignored)
  SimResiduals residuals;
};

// The collider's joint groups (BodyCollider's jointRegion) for a skeleton: 1 for the left arm chain
// (the joint whose name ends in "LeftArm", the upper arm in CMU and Mixamo naming, and every joint
// under it), 2 for the right one, 0 for the rest. A body that is one closed surface is split by them
// into arm and trunk contact regions, so that cloth in its armpit gets a plane of each.
std::vector<uint8_t> colliderJointGroups(const Skeleton& skeleton);

class ClothSolver {
 public:
  // Validates the character's body and skeleton against the mesh and prepares constraints, masses,
  // attachments and the collider prototype. Throws Error on bad input (including a garment that
  // starts inside the body by more than failPenetration).
  // `pathClearance` (may be empty): turns a pose's limbs out of the trunk in place, for the safer-path
  // retries (ClothSimSettings::saferPathRetries); without it those retries keep the dual-quaternion one.
  using PathClearance = std::function<void(Pose&)>;
  ClothSolver(const Character& character, SimulationMesh mesh, ClothSimSettings settings,
              PathClearance pathClearance = {});

  // Simulates one target pose. Thread-safe and deterministic: all state is local to the call, every
  // loop is sequential, so the same input gives bitwise the same output on any thread. Bad poses
  // (wrong joint count, non-finite rotations) and failed solves come back as !ok, never throw.
  PoseSimulation simulate(const Pose& target) const;

  // The residuals simulate() reports, measured on a shape made elsewhere (an external cloth tool's
  // result for `target`, simulation-mesh positions in character space): the worst edge stretch and
  // the depth inside the posed body; converged when the stretch is within convergedStrain.
  SimResiduals measure(const Pose& target, const Points3f& positions) const;

  const SimulationMesh& mesh() const { return mesh_; }
  const ClothSimSettings& settings() const { return settings_; }
  const std::vector<uint32_t>& attachedVertices() const { return attached_; }
  const ClothConstraints& constraints() const { return constraints_; }
  // A 64-bit digest of everything that decides the result (mesh, body, skeleton, settings): the pose
  // driver stores it with each result so that a re-run never reuses results of another setup.
  uint64_t fingerprint() const { return fingerprint_; }
  // The same without the settings that only a retry uses (retryCarries): a pose solved on its first
  // attempt under this digest is the pose it would be under any retry setting.
  uint64_t firstAttemptFingerprint() const { return firstAttemptFingerprint_; }

 private:
  // One attempt: the transition `slowdown` times slower with `slowdown` times the substeps, the cloth
  // carried by `carry`.
  // With `clearPath`, every frame's pose of the transition goes through pathClearance_ first.
  PoseSimulation simulateOnce(const Pose& target, int slowdown, ClothCarry carry, bool clearPath = false) const;
  std::vector<Mat4f> localSkinMatrices(const Pose& pose) const;
  float penetrationOf(const BodyCollider& body, const Vec3f& p) const;
  struct BodyAnchor;
  // Where an anchored vertex belongs on the posed body; false when it follows its own skinning.
  bool anchorTarget(const BodyAnchor& anchor, const BodyCollider& body, Vec3f& target) const;

  Skeleton skeleton_;
  SimulationMesh mesh_;
  ClothSimSettings settings_;
  Vec3f origin_;        // the solve's origin in character space
  Points3f restLocal_;  // simulation mesh rest positions relative to origin_
  ClothConstraints constraints_;
  ConstraintSchedule schedule_;  // constraints_' stretch, shear and bending blocks in dependency levels
  std::vector<uint32_t> attached_;
  std::vector<float> attachCompliance_;  // per attached vertex: 1 / its share of the band's stiffness
  // Where each attached vertex sits relative to the body in the rest pose: its closest body triangle
  // and the offset in that triangle's frame. The band follows the posed body surface, not the
  // garment's own skinning, which disagrees with the body's (different weights) and put shoulder
  // targets a centimetre inside the body, to be fought over by the attachment and the contacts.
  struct BodyAnchor {
    int triangle = -1;             // a triangle of the body's trunk; -1: none within reach, the
                                   // vertex follows its own skinning
    Vec2f uv = Vec2f::Zero();      // barycentrics of the triangle's corners 1 and 2
    Vec3f offset = Vec3f::Zero();  // in the triangle's (edge, normal x edge, normal) frame
  };
  std::vector<BodyAnchor> anchors_;
  // Half the median rest edge: the explosion test measures an edge's stretch relative to at least
  // this. A 1 mm edge moved 2 mm by a contact push reads as 200% relative to itself, yet it is
  // nothing like an explosion; what is, is a typical edge doubling.
  float shortEdgeFloor_ = 0.f;
  std::vector<Tether> tethers_;
  BodyCollider colliderPrototype_;
  PathClearance pathClearance_;
  uint64_t fingerprint_ = 0;
  uint64_t firstAttemptFingerprint_ = 0;
};

}  // namespace swish::bake
