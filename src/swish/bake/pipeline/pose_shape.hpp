#pragma once
// One recorded pose to the game-mesh shape the bake stores for it: the bake's source simulation of a
// single pose, in the steps that `swish bake` (part1_dataset.cpp) runs over its whole pose list and
// `swish replay --truth-every N` runs on single scene frames for ground truth. Both call this class,
// so the replay's truth is the shape the bake would have stored for that pose.
//
//   1. limb clearance (limb_clearance.hpp) turns limbs out of the trunk: the pose to simulate;
//   2. the cloth solver (cloth_solver.hpp) simulates the transition from the A-pose to that pose;
//   3. pose transfer (pose_transfer.hpp) binds the game mesh to the simulated cloth, smooths it
//      (Laplacian), un-skins it to pre-skinning space and bakes the normal map;
//   4. when the simulated pose differs from the recorded one (step 1 changed it), the world shape is
//      the pre-skin shape skinned with the RECORDED pose, as the run time will skin it, at the vertices
//      whose skinning the change moved (the others keep the simulated shape); with the cover on
//      (body_cover.hpp), the skin the simulated cloth covered is then kept covered in the recorded pose too.
//
// The bake keeps steps 1-3 apart (clearance over all poses first, then resumable per-pose simulation
// files), so each step is its own call; simulate() runs them all for one pose. Everything is const and
// deterministic: poses may be simulated on several threads at once with bitwise the same results.
#include <memory>
#include <string>
#include <vector>

#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/cloth/simulation_mesh.hpp"
#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/poses/limb_clearance.hpp"
#include "swish/bake/transfer/pose_transfer.hpp"

namespace swish::bake {

// What decides a pose's shape besides the character and the pose (bake config part1.simulation,
// .transfer, .normal_maps).
struct PoseShapeSettings {
  size_t simulationVertices = kDefaultSimulationVertices;  // 0: the welded game mesh, not subdivided
  ClothSimSettings simulation;
  LimbClearanceSettings limbClearance;  // clearance 0: poses are simulated as recorded
  PoseTransferSettings transfer;
};

// The pose as the bake simulates and stores it: the root joint at its rest rotation and translation
// (the shape is a function of the other joints' rotations; part1_dataset.hpp says why).
Pose canonicalPose(const Skeleton& skeleton, Pose pose);

struct PoseShape {
  bool ok = false;
  std::string failure;                      // why not, when !ok (the solver's reason)
  Pose simulatedPose;                       // the pose after limb clearance
  std::vector<LimbCorrection> corrections;  // what limb clearance changed (empty: nothing)
  Points3f gameMeshWorld;                   // character space, skinned with the recorded pose
  Points3f gameMeshPreSkin;
  NormalMapImage normalMap;
  SimResiduals residuals;
};

class PoseShapeSimulator {
 public:
  // Builds the simulation mesh, the limb clearance (when on), the solver and the transfer of
  // `character`, which must outlive this. Throws Error as those do (bad meshes, a garment that starts
  // inside the body, bad settings).
  PoseShapeSimulator(const Character& character, const PoseShapeSettings& settings);

  const Character& character() const { return *character_; }
  const PoseShapeSettings& settings() const { return settings_; }
  const LimbClearance* clearance() const { return clearance_.get(); }  // null when off
  const ClothSolver& solver() const { return solver_; }
  const PoseTransfer& transfer() const { return transfer_; }

  // Step 1: the pose to simulate (the recorded pose with its limbs out of the trunk); what changed is
  // appended to `corrections` when given.
  Pose poseToSimulate(const Pose& recorded, std::vector<LimbCorrection>* corrections = nullptr) const;
  // Steps 3 and 4, from the finished simulation (simulation-mesh positions) of `simulated`.
  TransferredPose gameMeshShape(const Pose& simulated, const Pose& recorded, const Points3f& simulationPositions) const;
  // Steps 1 to 4. A failed solve comes back as !ok with the reason; a transfer error too.
  PoseShape simulate(const Pose& recorded) const;

 private:
  const Character* character_;
  PoseShapeSettings settings_;
  std::shared_ptr<const LimbClearance> clearance_;  // null when off; shared with solver_'s path clearance
  ClothSolver solver_;
  PoseTransfer transfer_;
};

}  // namespace swish::bake
