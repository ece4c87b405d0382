// The per-pose chain: bind, follow, smooth, un-skin, bake.
#include <gtest/gtest.h>

#include "support/random_model.hpp"
#include "swish/bake/transfer/pose_transfer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

using namespace swish;
using namespace swish::bake;

TEST(PoseTransfer, SimulationEqualToSkinnedGameMeshRoundTripsToRestAndFlatMap) {
  Rng rng(test::testSeed(601));
  test::RandomModelSpec spec;
  spec.vertices = 120;
  const Model m = test::makeRandomModel(rng, spec);
  Character c;
  c.name = "random";
  c.skeleton = m.skeleton;
  c.garment = m.gameMesh;
  c.body = m.gameMesh;
  PoseTransferSettings s;
  s.normalMap.width = s.normalMap.height = 32;
  const PoseTransfer pt(c, c.garment.positions, c.garment.triangles, s);
  EXPECT_LT(pt.meshTransfer().maxBindingDistance(), 1e-6f);
  for (int k = 0; k < 3; ++k) {
    const Pose pose = test::makeRandomPose(rng, c.skeleton, 0.5f);
    const Points3f simPosed = skinPositions(c.garment.positions, c.garment.skin, c.skeleton.skinningMatrices(pose));
    const TransferredPose t = pt.transfer(pose, simPosed);
    // The cloth is exactly the skinned game mesh: nothing to smooth, nothing to bake.
    EXPECT_LT((t.gameMeshWorld - simPosed).cwiseAbs().maxCoeff(), 1e-4f);
    EXPECT_LT((t.gameMeshPreSkin - c.garment.positions).cwiseAbs().maxCoeff(), 1e-3f);
    EXPECT_LT(t.maxSmoothingShift, 1e-4f);
    EXPECT_GT(t.bakeStats.chartTexels, 0u);
    // The random test mesh is jagged (1 cm of noise on a 2 cm grid), so skinning folds it in places
    // and a few texel rays along the interpolated normal graze the surface and find another sheet.
    // Cloth does not fold like that; here we ask that almost every texel is flat.
    size_t flat = 0;
    for (size_t i = 0; i < t.normalMap.xy.size(); i += 2)
      flat += std::abs(t.normalMap.xy[i]) < 2e-3f && std::abs(t.normalMap.xy[i + 1]) < 2e-3f;
    EXPECT_GE(flat, size_t(0.98 * double(t.normalMap.xy.size() / 2))) << "pose " << k;
  }
  // A displaced cloth moves the game mesh and shows up in the normal map.
  const Pose pose = c.skeleton.restPose();
  Points3f bumped = c.garment.positions;
  for (Eigen::Index v = 0; v < bumped.rows(); v += 3) bumped(v, 1) += 0.002f;
  const TransferredPose t = pt.transfer(pose, bumped);
  EXPECT_GT((t.gameMeshWorld - c.garment.positions).cwiseAbs().maxCoeff(), 1e-4f);
  float largest = 0.f;
  for (float v : t.normalMap.xy) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 1e-3f);
  Character noUv = c;
  noUv.garment.uvs.resize(0, 2);
  EXPECT_THROW(PoseTransfer(noUv, c.garment.positions, c.garment.triangles, s), Error);
}
