// Mesh transfer (game mesh bound to the simulation mesh) and Laplacian smoothing.
#include <gtest/gtest.h>

#include <cmath>

#include "support/random_model.hpp"
#include "swish/bake/transfer/laplacian_smoothing.hpp"
#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

// An n x n grid over [0,1]^2 in the z = 0 plane. With splitColumn in 1..n-2 the vertices of that column
// are duplicated (a UV seam): triangles left of it use the originals, right of it the copies.
struct Grid {
  Points3f p;
  Triangles t;
};
Grid makeGrid(int n, int splitColumn = -1) {
  Grid g;
  const int extra = splitColumn > 0 ? n : 0;
  g.p.resize(n * n + extra, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) g.p.row(y * n + x) << float(x) / float(n - 1), float(y) / float(n - 1), 0.f;
  for (int y = 0; y < extra; ++y) g.p.row(n * n + y) = g.p.row(y * n + splitColumn);
  auto id = [&](int x, int y, bool rightOfSeam) {
    return uint32_t((splitColumn > 0 && x == splitColumn && rightOfSeam) ? n * n + y : y * n + x);
  };
  g.t.resize(2 * (n - 1) * (n - 1), 3);
  int k = 0;
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const bool right = splitColumn > 0 && x >= splitColumn;
      g.t.row(k++) << id(x, y, right), id(x + 1, y, right), id(x + 1, y + 1, right);
      g.t.row(k++) << id(x, y, right), id(x + 1, y + 1, right), id(x, y + 1, right);
    }
  return g;
}

// A closed-ish bumpy surface for transfer: the grid bent into a half cylinder.
Points3f bend(const Points3f& p, float angle) {
  Points3f out(p.rows(), 3);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const float a = angle * (p(i, 0) - 0.5f);
    const float r = 1.f + p(i, 2);
    out.row(i) << r * std::sin(a), p(i, 1), r * std::cos(a) - 1.f;
  }
  return out;
}

}  // namespace

TEST(TriangleRayScene, ClosestPointAndRayAgreeWithGeometry) {
  const Grid g = makeGrid(5);
  const TriangleRayScene scene(g.p, g.t, "grid");
  const SurfacePoint s = scene.closestPoint(Vec3f(0.3f, 0.6f, 0.25f));
  ASSERT_TRUE(s.found);
  EXPECT_NEAR(s.distance, 0.25f, 1e-6f);
  EXPECT_LT((s.point - Vec3f(0.3f, 0.6f, 0.f)).norm(), 1e-6f);
  const SurfacePoint outside = scene.closestPoint(Vec3f(1.5f, 0.5f, 0.f));
  EXPECT_NEAR(outside.distance, 0.5f, 1e-6f);
  const SurfacePoint r = scene.intersect(Vec3f(0.7f, 0.2f, 1.f), Vec3f(0, 0, -1), 0.f, 10.f);
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.distance, 1.f, 1e-6f);
  EXPECT_FALSE(scene.intersect(Vec3f(0.7f, 0.2f, 1.f), Vec3f(0, 0, -1), 0.f, 0.5f).found);
  Triangles bad = g.t;
  bad(0, 0) = 999;
  EXPECT_THROW(TriangleRayScene(g.p, bad, "bad"), Error);
}

TEST(MeshTransfer, IdenticalMeshIsExactInEveryPose) {
  const Grid g = makeGrid(9);
  const MeshTransfer transfer(g.p, g.t, g.p);
  EXPECT_LT(transfer.maxBindingDistance(), 1e-6f);
  for (float angle : {0.f, 1.f, 2.5f}) {
    const Points3f posed = bend(g.p, angle);
    const Points3f got = transfer.follow(posed);
    EXPECT_LT((got - posed).cwiseAbs().maxCoeff(), 2e-6f) << "angle " << angle;
  }
}

TEST(MeshTransfer, OffsetGameMeshKeepsItsDistanceWhenTheClothBends) {
  // Simulation mesh: a fine grid. Game mesh: a coarser grid 1 cm above it. Bending the cloth into a
  // cylinder of radius 1 must keep the game mesh on the cylinder of radius 1.01.
  const Grid sim = makeGrid(21);
  Grid game = makeGrid(6);
  game.p.col(2).setConstant(0.01f);
  const MeshTransfer transfer(sim.p, sim.t, game.p);
  EXPECT_NEAR(transfer.maxBindingDistance(), 0.01f, 1e-6f);
  const Points3f got = transfer.follow(bend(sim.p, 1.5f));
  const Points3f expect = bend(game.p, 1.5f);
  // Exact up to the chord error of the fine grid's flat triangles (~ r * (da)^2 / 8 ~ 7e-4).
  EXPECT_LT((got - expect).cwiseAbs().maxCoeff(), 1e-3f);
  for (Eigen::Index i = 0; i < got.rows(); ++i) {
    const float r = std::hypot(got(i, 0), got(i, 2) + 1.f);
    EXPECT_NEAR(r, 1.01f, 1e-3f);
  }
  EXPECT_THROW(transfer.follow(sim.p.topRows(5)), Error);
}

TEST(LaplacianSmoothing, ReducesJaggedNoiseAndKeepsSeamsWelded) {
  const int n = 15, seam = 7;
  const Grid g = makeGrid(n, seam);
  Rng rng(test::testSeed(401));
  Points3f noisy = g.p;
  for (int v = 0; v < n * n; ++v) noisy(v, 2) = float(rng.normal(0.0, 0.01));
  for (int y = 0; y < n; ++y) noisy.row(n * n + y) = noisy.row(y * n + seam);  // copies coincide
  const float before = umbrellaRoughness(noisy, g.t);
  for (auto weights : {LaplacianWeights::Uniform, LaplacianWeights::Cotangent}) {
    LaplacianSmoothingSettings s;
    s.weights = weights;
    s.strength = 0.5f;
    s.iterations = 10;
    const LaplacianSmoother smoother(g.t, g.p, s);
    EXPECT_EQ(smoother.weldedVertexCount(), size_t(n * n));
    const Points3f smooth = smoother.smooth(noisy);
    const float after = umbrellaRoughness(smooth, g.t);
    EXPECT_LT(after, 0.25f * before) << "before " << before << " after " << after;
    for (int y = 0; y < n; ++y) EXPECT_EQ(smooth.row(n * n + y), smooth.row(y * n + seam)) << "seam row " << y;
    // A flat plane stays exactly where it is (nothing to smooth), boundary included.
    EXPECT_LT((smoother.smooth(g.p) - g.p).cwiseAbs().maxCoeff(), 1e-6f);
  }
  // More strength or iterations smooth more.
  LaplacianSmoothingSettings weak, strong;
  weak.iterations = 1;
  strong.iterations = 20;
  EXPECT_LT(umbrellaRoughness(LaplacianSmoother(g.t, g.p, strong).smooth(noisy), g.t),
            umbrellaRoughness(LaplacianSmoother(g.t, g.p, weak).smooth(noisy), g.t));
  LaplacianSmoothingSettings bad;
  bad.strength = 1.5f;
  EXPECT_THROW(LaplacianSmoother(g.t, g.p, bad), Error);
}

TEST(LaplacianSmoothing, DisplacementSmoothingKeepsTheReferenceShape) {
  // A bent sheet with jagged offsets: smoothing the displacement from the bent reference removes the
  // jaggedness without flattening the bend, which absolute smoothing would start to do.
  const Grid g = makeGrid(15);
  const Points3f reference = bend(g.p, 2.f);
  Rng rng(test::testSeed(402));
  Points3f jagged = reference;
  for (Eigen::Index v = 0; v < jagged.rows(); ++v)
    for (int k = 0; k < 3; ++k) jagged(v, k) += float(rng.normal(0.0, 0.004));
  LaplacianSmoothingSettings s;
  s.iterations = 30;
  const LaplacianSmoother smoother(g.t, g.p, s);
  const Points3f viaDisplacement = smoother.smoothDisplacement(jagged, reference);
  const Points3f absolute = smoother.smooth(jagged);
  // RMS over vertices (the four pinned boundary corners keep their noise, so not the maximum).
  auto rms = [&](const Points3f& x) { return std::sqrt((x - reference).squaredNorm() / float(x.rows())); };
  const float errDisp = rms(viaDisplacement), errAbs = rms(absolute), errJagged = rms(jagged);
  EXPECT_LT(errDisp, 0.5f * errJagged);
  EXPECT_LT(errDisp, errAbs);
}
