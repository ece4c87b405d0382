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
// body poses. The bake simulates the corrected pose and stores the recorded one (dataset_builder.cpp).
//
// Parts are the body's connected components; the trunk is the one with the most triangles. A limb's
// root joint is the shallowest joint carrying a tenth of its skin weight. Only limb vertices that lie
// outside the trunk in the rest pose and farther than rootRadius from the root joint are checked:
// the root of a tube starts inside the trunk by construction. A body that is one connected mesh has
// no parts to separate, and a trunk that is not a closed surface has no inside; the poses of either
// are left unchanged (skipped() says why).
#include <optional>
#include <string>
#include <vector>

#include "swish/bake/body_collider.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

struct LimbClearanceSettings {
  float clearance = 0.015f;   // m between a limb and the trunk: room for two layers of cloth
  float rootRadius = 0.10f;   // m: limb vertices this close to their root joint are not checked
  float maxDegrees = 60.f;    // the largest correction; a limb still inside after it is reported
};

struct LimbCorrection {
  std::string joint;       // the root joint that was rotated
  float degrees = 0.f;     // by how much
  float depthBefore = 0.f;  // m: how far the limb was inside the clearance before
  float depthAfter = 0.f;   // after (0 when cleared)
};

class LimbClearance {
 public:
  // Throws Error on a body without skin weights or settings out of range.
  LimbClearance(const Character& character, LimbClearanceSettings settings = {});

  // Rotates limbs of `pose` out of the trunk in place; returns what it changed (empty: nothing).
  // Deterministic; non-finite poses are left alone for the solver to reject.
  std::vector<LimbCorrection> apply(Pose& pose) const;

  size_t limbCount() const { return limbs_.size(); }
  // Why no limb is checked (empty when some are).
  const std::string& skipped() const { return skipped_; }

 private:
  struct Limb {
    int rootJoint = -1;
    std::vector<uint32_t> vertices;  // checked vertices
    std::vector<float> restDistance;  // their signed distance to the trunk at rest
  };
  Skeleton skeleton_;
  Mesh body_;
  std::optional<BodyCollider> trunk_;  // the trunk alone, unposed: copied and posed per pose
  LimbClearanceSettings settings_;
  std::vector<Limb> limbs_;
  std::string skipped_;
};

}  // namespace swish::bake
