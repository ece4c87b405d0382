// Normal-map baking: analytic detail recovered in the game mesh's tangent frame, flat for identical
// meshes, mirrored charts, dilation of the texels outside the charts, determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "swish/bake/transfer/normal_map_baker.hpp"
#include "swish/bake/transfer/uv_dilation.hpp"
#include "swish/core/error.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

struct Sheet {
  Points3f p;
  Points2f uv;
  Triangles t;
};

// n x n grid over [x0, x1]^2 at height f(x, y); UV = (x, y) (or (1 - x, y) when mirrored).
template <class F>
Sheet makeSheet(int n, float x0, float x1, F height, bool mirrored = false) {
  Sheet s;
  s.p.resize(n * n, 3);
  s.uv.resize(n * n, 2);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float x = x0 + (x1 - x0) * float(i) / float(n - 1), y = x0 + (x1 - x0) * float(j) / float(n - 1);
      s.p.row(j * n + i) << x, y, height(x, y);
      s.uv.row(j * n + i) << (mirrored ? 1.f - x : x), y;
    }
  s.t.resize(2 * (n - 1) * (n - 1), 3);
  int k = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const uint32_t a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      // Winding is geometric (front face +z) even when the UVs are mirrored.
      s.t.row(k++) << a, b, c;
      s.t.row(k++) << a, c, d;
    }
  return s;
}

constexpr float kAmp = 0.008f, kFreq = 2.f;
float bump(float x, float y) {
  return kAmp * (std::sin(2.f * float(M_PI) * kFreq * x) + std::cos(2.f * float(M_PI) * kFreq * y));
}
Vec3f bumpNormal(float x, float y) {
  const float w = 2.f * float(M_PI) * kFreq;
  const float fx = kAmp * w * std::cos(w * x), fy = -kAmp * w * std::sin(w * y);
  return Vec3f(-fx, -fy, 1.f).normalized();
}

float angleDeg(const Vec3f& a, const Vec3f& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.f, 1.f)) * 180.f / float(M_PI);
}

}  // namespace

TEST(NormalMapBaker, RecoversAnAnalyticBumpInTheTangentFrame) {
  const Sheet game = makeSheet(2, 0.f, 1.f, [](float, float) { return 0.f; });  // one flat quad
  const Sheet sim = makeSheet(161, 0.f, 1.f, bump);
  NormalMapBakeSettings s;
  s.width = s.height = 64;
  const NormalMapBaker baker(game.uv, game.t, game.p, s);
  EXPECT_EQ(baker.chartTexelCount(), size_t(64 * 64));
  const MeshFrameTopology simTopo = buildFrameTopology(sim.t, sim.p);
  NormalMapBakeStats stats;
  const NormalMapImage im = baker.bake(game.p, sim.p, sim.t, simTopo, &stats);
  EXPECT_EQ(stats.hitTexels, size_t(64 * 64));
  EXPECT_EQ(stats.missedTexels, 0u);
  EXPECT_LE(stats.maxHitDistance, 2.f * kAmp + 1e-5f);
  float worst = 0.f, largestSlope = 0.f;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      const float u = (float(x) + .5f) / 64.f, v = (float(y) + .5f) / 64.f;
      const float X = im.xy[2 * (y * 64 + x)], Y = im.xy[2 * (y * 64 + x) + 1];
      const Vec3f got(X, Y, std::sqrt(std::max(0.f, 1.f - X * X - Y * Y)));
      const Vec3f expect = bumpNormal(u, v);  // game frame: T = +x, B = +y, N = +z
      worst = std::max(worst, angleDeg(got, expect));
      largestSlope = std::max(largestSlope, angleDeg(expect, Vec3f::UnitZ()));
    }
  EXPECT_GT(largestSlope, 8.f);  // the detail is real: up to ~8-9 degrees of tilt
  EXPECT_LT(worst, 0.5f) << "worst angular error " << worst << " deg";
}

TEST(NormalMapBaker, MirroredChartFlipsX) {
  const Sheet game = makeSheet(
      2, 0.f, 1.f, [](float, float) { return 0.f; }, true);
  const Sheet sim = makeSheet(161, 0.f, 1.f, bump);
  NormalMapBakeSettings s;
  s.width = s.height = 32;
  const NormalMapImage im =
      NormalMapBaker(game.uv, game.t, game.p, s).bake(game.p, sim.p, sim.t, buildFrameTopology(sim.t, sim.p));
  float worst = 0.f;
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      // Texel u maps to x = 1 - u; tangent = -x, bitangent = +y.
      const float px = 1.f - (float(x) + .5f) / 32.f, py = (float(y) + .5f) / 32.f;
      const Vec3f n = bumpNormal(px, py);
      worst = std::max(
          {worst, std::abs(im.xy[2 * (y * 32 + x)] - (-n.x())), std::abs(im.xy[2 * (y * 32 + x) + 1] - n.y())});
    }
  EXPECT_LT(worst, 0.01f);
}

TEST(NormalMapBaker, IdenticalMeshesGiveAFlatMapAndRunsRepeatExactly) {
  // A curved sheet baked against itself: the simulation normal equals the game normal everywhere.
  const Sheet m = makeSheet(23, 0.f, 1.f, [](float x, float y) { return 0.2f * x * x - 0.1f * y * x; });
  NormalMapBakeSettings s;
  s.width = s.height = 48;
  const NormalMapBaker baker(m.uv, m.t, m.p, s);
  const MeshFrameTopology topo = buildFrameTopology(m.t, m.p);
  const NormalMapImage a = baker.bake(m.p, m.p, m.t, topo);
  for (float v : a.xy) ASSERT_LT(std::abs(v), 1e-4f);
  const NormalMapImage b = baker.bake(m.p, m.p, m.t, topo);
  EXPECT_EQ(a.xy, b.xy);
}

TEST(NormalMapBaker, DilationFillsTheTexelsOutsideTheChart) {
  // The chart covers UV [0.25, 0.75]^2 of a 32x32 map: 8 texels of border all round.
  const Sheet game = makeSheet(2, 0.25f, 0.75f, [](float, float) { return 0.f; });
  const Sheet sim = makeSheet(81, 0.2f, 0.8f, bump);
  NormalMapBakeSettings s;
  s.width = s.height = 32;
  s.dilationRings = 4;
  NormalMapBakeStats stats;
  const NormalMapImage im =
      NormalMapBaker(game.uv, game.t, game.p, s).bake(game.p, sim.p, sim.t, buildFrameTopology(sim.t, sim.p), &stats);
  EXPECT_EQ(stats.chartTexels, size_t(16 * 16));
  EXPECT_EQ(stats.hitTexels, stats.chartTexels);
  // Rings 1..4 around the 16x16 chart: 24^2 - 16^2 texels dilated; the rest set flat.
  EXPECT_EQ(stats.dilatedTexels, size_t(24 * 24 - 16 * 16));
  EXPECT_EQ(stats.flatTexels, size_t(32 * 32 - 24 * 24));
  auto at = [&](int x, int y, int c) { return im.xy[2 * (y * 32 + x) + c]; };
  // The first ring copies its inside neighbour along the straight chart edge (mean of three that are
  // close): the map continues across the chart border instead of jumping to zero.
  for (int y = 9; y < 23; ++y) {
    EXPECT_NEAR(at(7, y, 0), (at(8, y - 1, 0) + at(8, y, 0) + at(8, y + 1, 0)) / 3.f, 1e-6f);
    EXPECT_GT(std::abs(at(7, y, 0)) + std::abs(at(7, y, 1)), 0.f);
  }
  EXPECT_EQ(at(0, 0, 0), 0.f);
  EXPECT_EQ(at(31, 31, 1), 0.f);
  for (float v : im.xy) EXPECT_TRUE(std::isfinite(v));
}

TEST(NormalMapBaker, RejectsBadInput) {
  const Sheet game = makeSheet(3, 0.f, 1.f, [](float, float) { return 0.f; });
  NormalMapBakeSettings s;
  EXPECT_THROW(NormalMapBaker(game.uv.topRows(4), game.t, game.p, s), Error);  // UV count
  s.width = 0;
  EXPECT_THROW(NormalMapBaker(game.uv, game.t, game.p, s), Error);
  s.width = 8;
  s.maxDistance = -1.f;
  EXPECT_THROW(NormalMapBaker(game.uv, game.t, game.p, s), Error);
  s.maxDistance = 0.01f;
  const NormalMapBaker baker(game.uv, game.t, game.p, s);
  const MeshFrameTopology topo = buildFrameTopology(game.t, game.p);
  EXPECT_THROW(baker.bake(game.p.topRows(3), game.p, game.t, topo), Error);
  Points3f nan = game.p;
  nan(0, 0) = std::nanf("");
  EXPECT_THROW(baker.bake(nan, game.p, game.t, topo), Error);
  // Dilation input sizes must agree.
  NormalMapImage im;
  im.width = im.height = 2;
  im.xy.assign(8, 0.f);
  std::vector<uint8_t> filled(3, 0);
  EXPECT_THROW(dilateNormalMap(im, filled, 1), Error);
}
