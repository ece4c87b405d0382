#pragma once
// Per pose, from the simulated high-resolution cloth to what the dataset stores: the game mesh bound
// to the simulation mesh (mesh_transfer.hpp), Laplacian-smoothed as a displacement from the game mesh
// skinned to the pose (laplacian_smoothing.hpp), un-skinned to pre-skinning space (core/skinning.hpp),
// and the normal map of the detail the smoothed game mesh lacks (normal_map_baker.hpp). Built once per
// character and simulation mesh; transfer() is const and may run for several poses at once.
#include <string>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/transfer/laplacian_smoothing.hpp"
#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/normal_map_baker.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {

struct PoseTransferSettings {
  LaplacianSmoothingSettings smoothing;
  NormalMapBakeSettings normalMap;
  UnskinSettings unskin;  // where the garment's skinning collapses (core/skinning.hpp)
};

struct TransferredPose {
  Points3f gameMeshWorld;
  Points3f gameMeshPreSkin;
  NormalMapImage normalMap;
  NormalMapBakeStats bakeStats;
  float maxSmoothingShift = 0.f;  // largest distance smoothing moved a vertex (metres)
  UnskinStats unskin;             // vertices whose skinning collapsed, un-skinned damped (core/skinning.hpp)
};

class PoseTransfer {
 public:
  // character.garment must have UVs and skin weights; simRest/simTriangles: the simulation mesh in
  // the rest pose. Throws Error for missing data.
  PoseTransfer(const Character& character, const Points3f& simRest, const Triangles& simTriangles,
               const PoseTransferSettings& settings);

  TransferredPose transfer(const Pose& pose, const Points3f& simPosed) const;

  const MeshTransfer& meshTransfer() const { return transfer_; }

 private:
  const Character* character_;
  UnskinSettings unskin_;
  Triangles simTriangles_;
  MeshFrameTopology simTopology_;
  MeshTransfer transfer_;
  LaplacianSmoother smoother_;
  NormalMapBaker baker_;
};

}  // namespace swish::bake
