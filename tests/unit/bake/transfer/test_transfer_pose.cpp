// The per-pose chain: bind, follow, smooth, un-skin, bake.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/random_model.hpp"
#include "swish/bake/transfer/pose_transfer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
// A random skinned mesh (120 vertices) as garment and body both.
Character randomCharacter(Rng& rng) {
  test::RandomModelSpec spec;
  spec.vertices = 120;
  const Model m = test::makeRandomModel(rng, spec);
  Character c;
  c.name = "random";
  c.skeleton = m.skeleton;
  c.garment = m.gameMesh;
  c.body = m.gameMesh;
  return c;
}
}  // namespace

TEST(PoseTransfer, SimulationEqualToSkinnedGameMeshRoundTripsToRestAndFlatMap) {
  Rng rng(test::testSeed(601));
  const Character c = randomCharacter(rng);
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

// The torn-shape measure: 0 at rest, the scale - 1 for a uniformly scaled shape (every edge above
// the half-median floor stretches by exactly that), and large where one vertex is thrown away.
TEST(PoseTransfer, WorstEdgeMeasuresStretchAgainstTheRestEdges) {
  Rng rng(test::testSeed(602));
  const Character c = randomCharacter(rng);
  PoseTransferSettings s;
  s.normalMap.width = s.normalMap.height = 32;
  const PoseTransfer pt(c, c.garment.positions, c.garment.triangles, s);
  EXPECT_LT(std::abs(pt.worstEdge(c.garment.positions).strain), 1e-5f);
  EXPECT_NEAR(pt.worstEdge(c.garment.positions * 1.5f).strain, 0.5f, 1e-4f);
  Points3f torn = c.garment.positions;
  const uint32_t thrown = uint32_t(c.garment.triangles(5, 1));
  torn(thrown, 0) += 1.f;  // a metre: the sheet of a torn sleeve
  const EdgeStretch w = pt.worstEdge(torn);
  EXPECT_GT(w.strain, 10.f);
  bool onEdgeOfThrown = w.vertex == thrown;
  for (Eigen::Index f = 0; f < c.garment.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (uint32_t(c.garment.triangles(f, k)) == thrown)
        for (int o = 0; o < 3; ++o) onEdgeOfThrown |= uint32_t(c.garment.triangles(f, o)) == w.vertex;
  EXPECT_TRUE(onEdgeOfThrown) << "worst edge at vertex " << w.vertex << ", thrown vertex " << thrown;
  torn(thrown, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(pt.worstEdge(torn).strain <= s.maxEdgeStrain);  // a non-finite shape never passes
}
