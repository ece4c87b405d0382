// VQ of a normal-map database against the BC5 baseline. Arguments: maps, map size, codebook size.
// The paper's case is 128 maps of 360x360 (1,036,800 blocks); the goal is <= 3 MB at an angular error
// no worse than BC5. Maps: smooth wrinkle-like sinusoids with random direction, frequency and phase
// (the real bake's maps come from part 1; this measures speed and the memory/error trade-off).
#include <benchmark/benchmark.h>

#include <cmath>

#include "swish/bake/compression/bc5_baseline.hpp"
#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

static std::vector<NormalMapImage> makeMaps(int count, uint32_t size) {
  Rng rng(91);
  std::vector<NormalMapImage> maps;
  for (int i = 0; i < count; ++i) {
    NormalMapImage m{size, size, std::vector<float>(size_t(size) * size * 2, 0.f)};
    for (int w = 0; w < 4; ++w) {
      const double angle = rng.uniform(0, M_PI), freq = rng.uniform(2, 12), phase = rng.uniform(0, 2 * M_PI);
      const double amp = rng.uniform(0.05, 0.25);
      for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
          const double u = (x + .5) / size, v = (y + .5) / size;
          const double s = std::cos(2 * M_PI * freq * (u * std::cos(angle) + v * std::sin(angle)) + phase);
          m.xy[2 * (size_t(y) * size + x)] += float(amp * s * std::cos(angle));
          m.xy[2 * (size_t(y) * size + x) + 1] += float(amp * s * std::sin(angle));
        }
    }
    maps.push_back(std::move(m));
  }
  return maps;
}

static void BM_VqDatabase(benchmark::State& state) {
  const auto maps = makeMaps(int(state.range(0)), uint32_t(state.range(1)));
  std::vector<const NormalMapImage*> ptrs;
  for (const auto& m : maps) ptrs.push_back(&m);
  VqOptions o;
  o.codebookSize = uint32_t(state.range(2));
  NormalMapDatabase db;
  db.keys = MatXf::Zero(Eigen::Index(maps.size()), 1);
  VqReport rep;
  for (auto _ : state) rep = encodeVq(ptrs, o, db);
  AngularErrorAccumulator vq, bc5;
  for (uint32_t m = 0; m < maps.size(); ++m) {
    vq.addMaps(maps[m], decodeVqMap(db, m));
    bc5.addMaps(maps[m], bc5RoundTrip(maps[m]));
  }
  const double bc5Total = double(maps.size()) * double(bc5Bytes(maps[0].width, maps[0].height));
  state.counters["vq_MB"] = double(rep.totalBytes()) / 1e6;
  state.counters["bc5_MB"] = bc5Total / 1e6;
  state.counters["bc5_over_vq"] = bc5Total / double(rep.totalBytes());
  state.counters["vq_mean_deg"] = vq.stats().meanDegrees;
  state.counters["vq_p95_deg"] = vq.stats().p95Degrees;
  state.counters["bc5_mean_deg"] = bc5.stats().meanDegrees;
  state.counters["bc5_p95_deg"] = bc5.stats().p95Degrees;
  state.counters["train_s"] = rep.trainingSeconds;
  state.counters["assign_s"] = rep.assignmentSeconds;
}
BENCHMARK(BM_VqDatabase)->Args({16, 128, 1024})->Args({128, 360, 4096})->Unit(benchmark::kSecond)->Iterations(1);

BENCHMARK_MAIN();
