// The game mesh kept over the body where the simulation covered it (bake/transfer/body_cover.hpp): a
// capsule body in a fine simulated tube 3 mm off it, and a coarse game tube (8 sides) on the same cloth
// whose flat sides cut 6 mm into the round body: the chords of the default jersey's long shoulder
// triangles, in a shape whose answer is known.
#include <gtest/gtest.h>

#include "support/cloth_fixture.hpp"
#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "swish/bake/transfer/body_cover.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

struct Scene {
  Mesh body, cloth, game;
};

Scene coarseTubeOnRoundBody(float clothGap = 0.003f, int gameRows = 24) {
  test::CapsuleSpec spec;
  spec.gap = clothGap;
  spec.garmentAround = 96;  // the simulated cloth: its chords are 0.07 mm deep
  Scene s;
  s.body = test::capsuleBody(spec);
  s.cloth = test::tubeGarment(spec);
  spec.gap = 0.003f;
  spec.garmentAround = 8;  // the game mesh: r (1 - cos(pi / 8)) = 9.4 mm deep chords
  spec.garmentRows = gameRows;
  s.game = test::tubeGarment(spec);
  return s;
}

// Body vertices whose nearest game triangle (inside it, away from the tube's open ends) has them in front
// of its outward side, and the deepest of them (m).
std::pair<size_t, float> bodyThrough(const Points3f& body, const Points3f& game, const Triangles& tris) {
  const TriangleRayScene mesh(game, tris, "test game mesh");
  size_t n = 0;
  float deepest = 0.f;
  for (Eigen::Index i = 0; i < body.rows(); ++i) {
    if (body(i, 1) < 0.12f || body(i, 1) > 0.55f) continue;  // the tube spans 0.05-0.62
    const Vec3f b = body.row(i);
    const SurfacePoint g = mesh.closestPoint(b, 0.03f);
    if (!g.found) continue;
    const Vec3f p0 = game.row(tris(g.triangle, 0)), p1 = game.row(tris(g.triangle, 1)),
                p2 = game.row(tris(g.triangle, 2));
    const float depth = (b - g.point).dot((p1 - p0).cross(p2 - p0).normalized());
    if (depth > 0.f) ++n, deepest = std::max(deepest, depth);
  }
  return {n, deepest};
}

}  // namespace

TEST(BodyCover, ACoarseGameMeshIsMovedOverTheBodyTheSimulationCovered) {
  const Scene s = coarseTubeOnRoundBody();
  const auto [before, deepBefore] = bodyThrough(s.body.positions, s.game.positions, s.game.triangles);
  ASSERT_GT(before, 100u);
  EXPECT_NEAR(deepBefore, 0.0094f - 0.003f, 0.0015f);  // the chord's depth less the cloth's gap

  BodyCoverSettings settings;  // 2 mm margin
  const BodyCover cover(s.game.positions, s.game.triangles, s.body.positions, s.body.triangles, settings);
  Points3f game = s.game.positions;
  const BodyCoverStats stats = cover.apply(game, s.body.positions, s.cloth.positions, s.cloth.triangles);
  EXPECT_GT(stats.samplesThrough, 100u);
  EXPECT_EQ(stats.samplesLeft, 0u);
  EXPECT_NEAR(stats.deepest, deepBefore, 0.002f);
  const auto [after, deepAfter] = bodyThrough(s.body.positions, game, s.game.triangles);
  EXPECT_EQ(after, 0u) << "deepest " << deepAfter;
  // Moved out by about the chord's depth, not more than the bound, and the seam's two copies together.
  EXPECT_GT(stats.largestShift, 0.005f);
  EXPECT_LE(stats.largestShift, settings.maxShift);
  EXPECT_GT(stats.verticesMoved, 50u);
  const int around = 8;
  for (int row = 0; row <= 24; ++row) {
    const Eigen::Index first = row * (around + 1), copy = first + around;
    EXPECT_EQ(game.row(first), game.row(copy)) << "row " << row;
  }
  // Only outwards, never along the tube: every vertex keeps its height and none comes nearer the axis.
  EXPECT_TRUE(game.allFinite());
  EXPECT_LT((game.col(1) - s.game.positions.col(1)).cwiseAbs().maxCoeff(), 1e-5f);
  for (Eigen::Index v = 0; v < game.rows(); ++v)
    EXPECT_GE(Vec2f(game(v, 0), game(v, 2)).norm(),
              Vec2f(s.game.positions(v, 0), s.game.positions(v, 2)).norm() - 1e-6f);
  // Deterministic.
  Points3f again = s.game.positions;
  cover.apply(again, s.body.positions, s.cloth.positions, s.cloth.triangles);
  EXPECT_EQ(again, game);
}

// A crumpled game mesh (each vertex thrown up to 6 mm off the tube, as a sleeve skinned back against the trunk
// folds): its vertex normals point every way, and moving along them tore edges between vertices that both
// moved (the corpus: 469 of 3918 poses past the 400 % bound). The cover moves the way the asking triangles
// face, and takes back part of the moves at the ends of any edge it would still stretch past 200 % strain
// (and past its length before).
TEST(BodyCover, ACrumpledGameMeshIsCoveredWithoutATear) {
  const int rows = 96;  // 6 mm apart: the bump's rings span a few cm
  const Scene s = coarseTubeOnRoundBody(0.003f, rows);
  Rng rng(test::testSeed(19));
  Points3f crumpled = s.game.positions;
  for (Eigen::Index v = 0; v < crumpled.rows(); ++v)
    for (int k = 0; k < 3; ++k) crumpled(v, k) += float(rng.uniform(-0.006, 0.006));
  const int around = 8;  // the seam's copies together, as a transfer keeps them
  for (int row = 0; row <= rows; ++row) crumpled.row(row * (around + 1) + around) = crumpled.row(row * (around + 1));
  const BodyCover cover(s.game.positions, s.game.triangles, s.body.positions, s.body.triangles, BodyCoverSettings{});
  Points3f game = crumpled;
  const BodyCoverStats stats = cover.apply(game, s.body.positions, s.cloth.positions, s.cloth.triangles);
  ASSERT_GT(stats.samplesThrough, 100u);
  EXPECT_LT(stats.samplesLeft, stats.samplesThrough / 4);
  EXPECT_GT(stats.verticesHeld, 0u);  // the bound was needed: the case this is for
  const Triangles& t = s.game.triangles;
  float worst = 0.f;  // the largest stretch past the bound, in rest lengths
  for (Eigen::Index k = 0; k < t.rows(); ++k)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t(k, e), b = t(k, (e + 1) % 3);
      const float rest = (s.game.positions.row(a) - s.game.positions.row(b)).norm();
      const float bound = std::max((crumpled.row(a) - crumpled.row(b)).norm(), 3.f * rest);
      worst = std::max(worst, ((game.row(a) - game.row(b)).norm() - bound) / rest);
    }
  EXPECT_LE(worst, 1e-4f);
}

TEST(BodyCover, NothingMovesWhereTheSimulationLeftTheBodyThroughOrWhenOff) {
  // The simulated cloth itself 5 mm inside the body: the transfer is not what put the body through.
  const Scene sunk = coarseTubeOnRoundBody(-0.005f);
  const BodyCover cover(sunk.game.positions, sunk.game.triangles, sunk.body.positions, sunk.body.triangles,
                        BodyCoverSettings{});
  Points3f game = sunk.game.positions;
  const BodyCoverStats stats = cover.apply(game, sunk.body.positions, sunk.cloth.positions, sunk.cloth.triangles);
  EXPECT_EQ(stats.verticesMoved, 0u);
  EXPECT_EQ(game, sunk.game.positions);

  const Scene s = coarseTubeOnRoundBody();
  BodyCoverSettings off;
  off.margin = 0.f;
  EXPECT_FALSE(off.enabled());
  const BodyCover none(s.game.positions, s.game.triangles, s.body.positions, s.body.triangles, off);
  game = s.game.positions;
  EXPECT_EQ(none.apply(game, s.body.positions, s.cloth.positions, s.cloth.triangles).verticesMoved, 0u);
  EXPECT_EQ(game, s.game.positions);
}

TEST(BodyCover, BadInputIsAClearError) {
  const Scene s = coarseTubeOnRoundBody();
  BodyCoverSettings bad;
  bad.margin = 0.5f;
  EXPECT_NE(test::errorOf([&] {
              BodyCover(s.game.positions, s.game.triangles, s.body.positions, s.body.triangles, bad);
            }).find("margin must be in"),
            std::string::npos);
  const BodyCover cover(s.game.positions, s.game.triangles, s.body.positions, s.body.triangles, BodyCoverSettings{});
  Points3f fewer = s.game.positions.topRows(10);
  EXPECT_NE(test::errorOf([&] {
              cover.apply(fewer, s.body.positions, s.cloth.positions, s.cloth.triangles);
            }).find("the game mesh has 10 vertices"),
            std::string::npos);
  // A mask of covered samples (coveredSamples) made for another body.
  Points3f game = s.game.positions;
  const std::vector<char> mask(5, 1);
  EXPECT_NE(test::errorOf([&] { cover.apply(game, s.body.positions, mask); }).find("do not belong to this body"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              cover.coveredSamples(s.body.positions.topRows(10), s.cloth.positions, s.cloth.triangles);
            }).find("the posed body has 10 vertices"),
            std::string::npos);
}
