#pragma once
// Per pose, from the simulated high-resolution cloth to what the dataset stores: the game mesh bound
// to the simulation mesh (mesh_transfer.hpp), Laplacian-smoothed as a displacement from the game mesh
// skinned to the pose (laplacian_smoothing.hpp), un-skinned to pre-skinning space (core/skinning.hpp),
// and the normal map of the detail the smoothed game mesh lacks (normal_map_baker.hpp). Built once per
// character and simulation mesh; transfer() is const and may run for several poses at once.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/transfer/body_cover.hpp"
#include "swish/bake/transfer/laplacian_smoothing.hpp"
#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/normal_map_baker.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {

struct PoseTransferSettings {
  LaplacianSmoothingSettings smoothing;
  NormalMapBakeSettings normalMap;
  UnskinSettings unskin;  // where the garment's skinning collapses (core/skinning.hpp)
  // A torn shape is not training data. A game-mesh edge stretched beyond this strain (4: five times
  // its rest length, or half the median rest edge where that is longer) fails the pose. Measured on
  // the corpus bake's 1960 poses (docs/baking.md): the worst edge of a pose is 2.8x its length at the
  // median, 4.4x at p99; of the 13 above 5x the worst are sleeves torn into sheets (edges 32x), which
  // the re-skinning of a pose limb clearance changed (pose_shape.hpp) or the solver left.
  float maxEdgeStrain = 4.f;
  // A pose whose limbs the limb clearance turned is simulated with them turned and its game-mesh shape
  // carried to the recorded pose through pre-skin space (B_recorded * B_simulated^-1, per vertex:
  // pose_shape.cpp). Where B_simulated nearly collapses (its smallest singular value s below twice
  // this) that carry amplifies the cloth's offset from the body up to 1 / s and tears the armpit; there
  // the vertex moves by its skinned rest position's displacement instead (B_recorded - B_simulated
  // applied to its rest position: bounded, the offset keeps its direction), fully below this value and
  // blended smoothly up to twice it. 0: the carry through pre-skin space everywhere (models baked
  // before it was a setting). Measured on the default bake's 3929 poses (docs/baking.md): 0.4 keeps
  // all 15 poses that tore, and moves the others' shapes 0.15 mm on average.
  float reskinMinSingularValue = 0.4f;
  // The game mesh kept `cover.margin` outside the body where the simulation's cloth covers it
  // (body_cover.hpp): its coarse triangles are chords that cut under sharp shoulders. margin 0: off
  // (models baked before it was a setting).
  BodyCoverSettings cover;
};

// The game mesh's worst edge in a shape: its strain (length / max(rest length, half the median rest
// edge) - 1) and one of its vertices.
struct EdgeStretch {
  float strain = 0.f;
  uint32_t vertex = 0;
};

struct TransferredPose {
  Points3f gameMeshWorld;
  Points3f gameMeshPreSkin;
  NormalMapImage normalMap;
  NormalMapBakeStats bakeStats;
  float maxSmoothingShift = 0.f;  // largest distance smoothing moved a vertex (metres)
  BodyCoverStats cover;           // what keeping the game mesh over the body did (nothing when off)
  BodyCoverStats coverRecorded;   // the same again in the recorded pose, after limb clearance (pose_shape.hpp)
};

class PoseTransfer {
 public:
  // character.garment must have UVs and skin weights; simRest/simTriangles: the simulation mesh in
  // the rest pose. Throws Error for missing data.
  PoseTransfer(const Character& character, const Points3f& simRest, const Triangles& simTriangles,
               const PoseTransferSettings& settings);

  TransferredPose transfer(const Pose& pose, const Points3f& simPosed) const;

  const MeshTransfer& meshTransfer() const { return transfer_; }
  const BodyCover* cover() const { return cover_ ? &*cover_ : nullptr; }  // null when off
  const Triangles& simulationTriangles() const { return simTriangles_; }
  // The worst edge of a game-mesh shape (world or pre-skin), against the game mesh's rest edges.
  EdgeStretch worstEdge(const Points3f& gameMeshShape) const;

 private:
  const Character* character_;
  UnskinSettings unskin_;
  std::vector<std::pair<uint32_t, uint32_t>> edges_;  // the game mesh's unique edges
  std::vector<float> edgeRest_;                       // their rest lengths, floored at half the median
  Triangles simTriangles_;
  MeshFrameTopology simTopology_;
  MeshTransfer transfer_;
  LaplacianSmoother smoother_;
  std::optional<BodyCover> cover_;  // when on and the character has a body
  NormalMapBaker baker_;
};

}  // namespace swish::bake
