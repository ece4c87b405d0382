// Normal-map bake speed: one 360x360 map of a game mesh against a simulation mesh of about 12,000
// vertices with wrinkle-like detail (the default resolution), and the transfer (follow + smoothing).
#include <benchmark/benchmark.h>

#include <cmath>

#include "swish/bake/transfer/laplacian_smoothing.hpp"
#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/normal_map_baker.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

struct Sheet {
  Points3f p;
  Points2f uv;
  Triangles t;
};

// A cylinder (torso-like) of n x n vertices, 0.3 m radius, 0.6 m tall; UVs unwrap it (with a seam).
Sheet cylinder(int n, float wrinkle) {
  Sheet s;
  s.p.resize(n * n, 3);
  s.uv.resize(n * n, 2);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float u = float(i) / float(n - 1), v = float(j) / float(n - 1);
      const float a = 2.f * float(M_PI) * u * 0.999f;
      const float r = 0.3f + wrinkle * std::sin(40.f * v + 6.f * a) * std::sin(25.f * u);
      s.p.row(j * n + i) << r * std::cos(a), 0.6f * v, r * std::sin(a);
      s.uv.row(j * n + i) << 0.02f + 0.96f * u, 0.02f + 0.96f * v;
    }
  s.t.resize(2 * (n - 1) * (n - 1), 3);
  int k = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const uint32_t a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      s.t.row(k++) << a, c, b;
      s.t.row(k++) << a, d, c;
    }
  return s;
}

void BM_BakeNormalMap360(benchmark::State& state) {
  const Sheet game = cylinder(40, 0.f);     // 1,600 vertices
  const Sheet sim = cylinder(110, 0.004f);  // 12,100 vertices with wrinkles
  const NormalMapBaker baker(game.uv, game.t, game.p, {});
  const MeshFrameTopology topo = buildFrameTopology(sim.t, sim.p);
  NormalMapBakeStats stats;
  for (auto _ : state) {
    NormalMapImage im = baker.bake(game.p, sim.p, sim.t, topo, &stats);
    benchmark::DoNotOptimize(im.xy.data());
  }
  state.counters["chartTexels"] = double(stats.chartTexels);
  state.counters["hitTexels"] = double(stats.hitTexels);
  state.counters["texels/s"] =
      benchmark::Counter(double(stats.chartTexels), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_BakeNormalMap360)->Unit(benchmark::kMillisecond);

void BM_TransferAndSmooth(benchmark::State& state) {
  const Sheet game = cylinder(40, 0.f);
  const Sheet sim = cylinder(110, 0.004f);
  const MeshTransfer transfer(sim.p, sim.t, game.p);
  const LaplacianSmoother smoother(game.t, game.p, {});
  for (auto _ : state) {
    Points3f g = smoother.smoothDisplacement(transfer.follow(sim.p), game.p);
    benchmark::DoNotOptimize(g.data());
  }
}
BENCHMARK(BM_TransferAndSmooth)->Unit(benchmark::kMillisecond);

void BM_BindGameMesh(benchmark::State& state) {
  const Sheet game = cylinder(40, 0.f);
  const Sheet sim = cylinder(110, 0.004f);
  for (auto _ : state) {
    MeshTransfer transfer(sim.p, sim.t, game.p);
    benchmark::DoNotOptimize(&transfer);
  }
}
BENCHMARK(BM_BindGameMesh)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
