#include "swish/bake/pipeline/pose_shape.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <Eigen/SVD>

#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {

namespace {

std::shared_ptr<const LimbClearance> makeClearance(const Character& c, const LimbClearanceSettings& s) {
  if (s.clearance > 0.f) return std::make_shared<const LimbClearance>(c, s);
  return nullptr;
}

// The solver's path clearance (ClothSimSettings::saferPathRetries): the same limb clearance as the
// targets', on each frame of the transition. It shares the simulator's (apply is const), so it does not
// depend on where the simulator lives.
ClothSolver::PathClearance pathClearanceOf(const std::shared_ptr<const LimbClearance>& clearance) {
  if (!clearance) return {};
  return [clearance](Pose& p) { clearance->apply(p); };
}

}  // namespace

Pose canonicalPose(const Skeleton& skeleton, Pose p) {
  p.local[0] = skeleton.joints[0].rest.rotation;
  p.rootTranslation = skeleton.joints[0].rest.translation;
  return p;
}

PoseShapeSimulator::PoseShapeSimulator(const Character& character, const PoseShapeSettings& settings)
    : character_(&character),
      settings_(settings),
      clearance_(makeClearance(character, settings.limbClearance)),
      solver_(character, buildSimulationMesh(character, settings.simulationVertices), settings.simulation,
              pathClearanceOf(clearance_)),
      transfer_(character, solver_.mesh().restPositions, solver_.mesh().triangles, settings.transfer) {}

Pose PoseShapeSimulator::poseToSimulate(const Pose& recorded, std::vector<LimbCorrection>* corrections) const {
  Pose p = recorded;
  if (clearance_) {
    std::vector<LimbCorrection> c = clearance_->apply(p);
    if (corrections) corrections->insert(corrections->end(), c.begin(), c.end());
  }
  return p;
}

TransferredPose PoseShapeSimulator::gameMeshShape(const Pose& simulated, const Pose& recorded,
                                                  const Points3f& simulationPositions) const {
  TransferredPose tp = transfer_.transfer(simulated, simulationPositions);
  // A pose whose limbs were turned out of the trunk: the shape before skinning comes from the
  // corrected simulation; the world shape is that shape skinned as the run time will skin it with
  // the recorded pose. The model so learns its real inputs, and the sleeves of a hanging arm pass
  // into the torso with the arm, as the body does.
  //
  // Only the vertices whose skinning the correction changed, i.e. weighted on a joint it moved. Elsewhere
  // both poses skin alike, and the round trip through pre-skin space would give the simulated shape
  // back, except where un-skinning damps a collapsed matrix (core/skinning.hpp): an armpit vertex half
  // on the spine and half on a raised arm then falls towards its collapsed rest position while its
  // neighbours stay where the cloth is: a thigh turned out of the crotch alone tore the jersey under
  // the arms. On the session-19 default bake's 3884 cached simulations 13 poses tear instead of 25 (7
  // of 10 torn poses looked at had only a thigh turned; the worst edge 163-354 % as simulated,
  // 448-3170 % round-tripped).
  //
  // Where the simulated pose's blend of a vertex nearly collapses (an armpit vertex half on the spine,
  // half on an arm the correction raised), the round trip amplifies the cloth's offset from the body
  // and tears the armpit (pose_transfer.hpp, reskinMinSingularValue); there the vertex moves with its
  // skinned rest position instead, and its pre-skin position is taken back through the recorded pose's
  // blend, so that the run time's skinning gives the shape stored here.
  const SkinWeights& skin = character_->garment.skin;
  const Mesh& garment = character_->garment;
  const std::vector<Mat4f> simulatedMatrices = character_->skeleton.skinningMatrices(simulated);
  const std::vector<Mat4f> recordedMatrices = character_->skeleton.skinningMatrices(recorded);
  std::vector<char> moved(recordedMatrices.size(), 0);
  for (size_t j = 0; j < moved.size(); ++j) moved[j] = simulatedMatrices[j] != recordedMatrices[j];
  if (std::find(moved.begin(), moved.end(), 1) != moved.end()) {
    const Points3f reskinned = skinPositions(tp.gameMeshPreSkin, skin, recordedMatrices);
    const float lo = settings_.transfer.reskinMinSingularValue, hi = 2.f * lo;
    std::vector<Eigen::Index> carried;  // vertices moved (partly) with their skinned rest position
    for (Eigen::Index v = 0; v < tp.gameMeshWorld.rows(); ++v) {
      bool onMoved = false;
      for (size_t k = size_t(v) * size_t(skin.influences); k < size_t(v + 1) * size_t(skin.influences); ++k)
        onMoved = onMoved || (skin.weights[k] > 0.f && moved[skin.joints[k]]);
      if (!onMoved) continue;
      float w = 1.f;  // the round trip's share
      Mat4f bs = Mat4f::Identity();
      if (lo > 0.f) {
        bs = blendedSkinMatrix(skin, size_t(v), simulatedMatrices);
        const float s = Eigen::JacobiSVD<Mat3f>(bs.topLeftCorner<3, 3>()).singularValues().minCoeff();
        const float x = std::clamp((s - lo) / (hi - lo), 0.f, 1.f);
        w = x * x * (3.f - 2.f * x);  // smoothstep: no seam where the blend starts
      }
      if (w >= 1.f) {
        tp.gameMeshWorld.row(v) = reskinned.row(v);
        continue;
      }
      const Mat4f br = blendedSkinMatrix(skin, size_t(v), recordedMatrices);
      const Vec3f rest = garment.positions.row(v).transpose();
      const Vec3f shifted = tp.gameMeshWorld.row(v).transpose() + (br - bs).topLeftCorner<3, 3>() * rest +
                            (br - bs).topRightCorner<3, 1>();
      tp.gameMeshWorld.row(v) = (w * reskinned.row(v).transpose() + (1.f - w) * shifted).transpose();
      carried.push_back(v);
    }
    if (!carried.empty()) {
      // Stored is what the run time can draw: the recorded pose's skinning of the pre-skin position. Where
      // that blend collapses too, un-skinning damps (core/skinning.hpp) and the shape moves to the nearest
      // drawable one; a world shape no pre-skin shape gives would be error no model can take away.
      const Points3f preSkin =
          unskinPositions(tp.gameMeshWorld, garment.positions, skin, recordedMatrices, settings_.transfer.unskin);
      for (Eigen::Index v : carried) tp.gameMeshPreSkin.row(v) = preSkin.row(v);
      const Points3f drawn = skinPositions(tp.gameMeshPreSkin, skin, recordedMatrices);
      for (Eigen::Index v : carried) tp.gameMeshWorld.row(v) = drawn.row(v);
    }
    // The cover again, in the recorded pose (body_cover.hpp). The sleeve was simulated round an arm that
    // limb clearance turned out of the trunk; skinned back with the recorded arm, the arm's skin (on its
    // own weights) passes through the sleeve's inner side by the armpit, which the cover of step 3, in the
    // simulated pose, cannot see (measured: docs/baking.md, "The cover on the truth"). The skin the
    // simulation covered in its pose is kept covered in the recorded one: the same body samples, posed as
    // recorded. The stored shape moves by what the run time draws of the cover's move.
    if (const BodyCover* cover = settings_.transfer.cover.recordedPose ? transfer_.cover() : nullptr) {
      const Mesh& body = character_->body;
      const std::vector<char> covered =
          cover->coveredSamples(skinPositions(body.positions, body.skin, simulatedMatrices), simulationPositions,
                                transfer_.simulationTriangles());
      Points3f world = tp.gameMeshWorld;
      tp.coverRecorded = cover->apply(world, skinPositions(body.positions, body.skin, recordedMatrices), covered);
      if (tp.coverRecorded.verticesMoved > 0) {
        std::vector<Eigen::Index> shifted;
        for (Eigen::Index v = 0; v < world.rows(); ++v)
          if (world.row(v) != tp.gameMeshWorld.row(v)) shifted.push_back(v);
        // The cover's move, un-skinned and drawn (core/skinning.hpp): where the recorded pose's blend collapses
        // the stored shape is one no pre-skin shape draws, and re-skinning such a vertex whole would jump it
        // to the drawable shape (measured on a corpus pose: a 0.3 mm move drawn 43 mm away, the edge torn).
        moveSkinnedShape(tp.gameMeshWorld, tp.gameMeshPreSkin, world - tp.gameMeshWorld, shifted, skin,
                         recordedMatrices, settings_.transfer.unskin);
      }
    }
  }
  const EdgeStretch worst = transfer_.worstEdge(tp.gameMeshWorld);
  if (!(worst.strain <= settings_.transfer.maxEdgeStrain)) {
    const uint16_t joint = character_->garment.skin.strongestJoint(worst.vertex);
    char line[300];
    std::snprintf(line, sizeof line,
                  "the game mesh is torn: an edge at game vertex %u (near joint '%s') is stretched %.0f%% "
                  "(bound %.0f%%: part1.transfer.max_edge_strain)",
                  worst.vertex, character_->skeleton.joints[joint].name.c_str(), 100.0 * worst.strain,
                  100.0 * settings_.transfer.maxEdgeStrain);
    throw Error(line);
  }
  return tp;
}

PoseShape PoseShapeSimulator::simulate(const Pose& recorded) const {
  PoseShape out;
  out.simulatedPose = poseToSimulate(recorded, &out.corrections);
  PoseSimulation sim = solver_.simulate(out.simulatedPose);
  out.residuals = sim.residuals;
  if (!sim.ok) {
    out.failure = "simulation: " + sim.failure;
    return out;
  }
  try {
    TransferredPose tp = gameMeshShape(out.simulatedPose, recorded, sim.positions);
    out.gameMeshWorld = std::move(tp.gameMeshWorld);
    out.gameMeshPreSkin = std::move(tp.gameMeshPreSkin);
    out.normalMap = std::move(tp.normalMap);
    out.ok = true;
  } catch (const Error& e) {
    out.failure = std::string("transfer: ") + e.what();
  }
  return out;
}

}  // namespace swish::bake
