#include "swish/bake/transfer/pose_transfer.hpp"

#include <algorithm>
#include <cmath>

#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"
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
      baker_(character.garment.uvs, character.garment.triangles, character.garment.positions, settings.normalMap) {
  const Points3f& p = character.garment.positions;
  edges_ = uniqueEdges(buildVertexNeighbours(character.garment.triangles, size_t(p.rows())));
  edgeRest_ = edgeLengths(p, edges_);
  if (settings.cover.enabled() && character.body.triangleCount() > 0)
    cover_.emplace(character.garment.positions, character.garment.triangles, character.body.positions,
                   character.body.triangles, settings.cover);
  if (!edgeRest_.empty()) {
    std::vector<float> sorted = edgeRest_;
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
    const float floor = 0.5f * sorted[sorted.size() / 2];
    for (float& l : edgeRest_) l = std::max(l, floor);
  }
}

EdgeStretch PoseTransfer::worstEdge(const Points3f& shape) const {
  EdgeStretch w;
  for (size_t e = 0; e < edges_.size(); ++e) {
    const auto [a, b] = edges_[e];
    const float strain = (shape.row(a) - shape.row(b)).norm() / edgeRest_[e] - 1.f;
    if (strain > w.strain || !std::isfinite(strain)) {
      w = {strain, a};
      if (!std::isfinite(strain)) break;
    }
  }
  return w;
}

TransferredPose PoseTransfer::transfer(const Pose& pose, const Points3f& simPosed) const {
  const Mesh& g = character_->garment;
  const auto mats = character_->skeleton.skinningMatrices(pose);
  const Points3f followed = transfer_.follow(simPosed);
  const Points3f skinned = skinPositions(g.positions, g.skin, mats);
  TransferredPose out;
  out.gameMeshWorld = smoother_.smoothDisplacement(followed, skinned);
  out.maxSmoothingShift = (out.gameMeshWorld - followed).rowwise().norm().maxCoeff();
  if (cover_) {
    const Mesh& body = character_->body;
    out.cover =
        cover_->apply(out.gameMeshWorld, skinPositions(body.positions, body.skin, mats), simPosed, simTriangles_);
  }
  out.gameMeshPreSkin = unskinPositions(out.gameMeshWorld, g.positions, g.skin, mats, unskin_);
  out.normalMap = baker_.bake(out.gameMeshWorld, simPosed, simTriangles_, simTopology_, &out.bakeStats);
  return out;
}

}  // namespace swish::bake
