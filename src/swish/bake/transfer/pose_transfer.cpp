#include "swish/bake/transfer/pose_transfer.hpp"

#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {
namespace {

const Character& checked(const Character& c) {
  const std::string what = "pose transfer: garment of '" + c.name + "'";
  c.garment.validate(what, c.skeleton.size());
  if (c.garment.uvs.rows() != c.garment.positions.rows()) throw Error(what + ": has no UVs for the normal map");
  if (c.garment.skin.vertexCount() != c.garment.vertexCount()) throw Error(what + ": has no skin weights");
  return c;
}

}  // namespace

PoseTransfer::PoseTransfer(const Character& character, const Points3f& simRest, const Triangles& simTriangles,
                           const PoseTransferSettings& settings)
    : character_(&checked(character)),
      unskin_(settings.unskin),
      simTriangles_(simTriangles),
      simTopology_(buildFrameTopology(simTriangles, simRest)),
      transfer_(simRest, simTriangles, character.garment.positions, "pose transfer: binding the game mesh"),
      smoother_(character.garment.triangles, character.garment.positions, settings.smoothing),
      baker_(character.garment.uvs, character.garment.triangles, character.garment.positions, settings.normalMap) {}

TransferredPose PoseTransfer::transfer(const Pose& pose, const Points3f& simPosed) const {
  const Mesh& g = character_->garment;
  const auto mats = character_->skeleton.skinningMatrices(pose);
  const Points3f followed = transfer_.follow(simPosed);
  const Points3f skinned = skinPositions(g.positions, g.skin, mats);
  TransferredPose out;
  out.gameMeshWorld = smoother_.smoothDisplacement(followed, skinned);
  out.maxSmoothingShift = (out.gameMeshWorld - followed).rowwise().norm().maxCoeff();
  out.gameMeshPreSkin = unskinPositions(out.gameMeshWorld, g.positions, g.skin, mats, unskin_, &out.unskin);
  out.normalMap = baker_.bake(out.gameMeshWorld, simPosed, simTriangles_, simTopology_, &out.bakeStats);
  return out;
}

}  // namespace swish::bake
