// Nearest normal-map code: brute force over the database keys (paper: 128 maps). Goal <= 0.2 us for
// 128 keys. Code dimensions 8..32; also the portable kernel, and 1024 keys to show the scaling.
//
//   build-*/tests/bench_lookup --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <vector>

#include "swish/core/rng.hpp"
#include "swish/runtime/nearest_code.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

void runLookup(benchmark::State& state, CpuKernel kernel) {
  const int maps = int(state.range(0)), dims = int(state.range(1));
  Rng rng(uint64_t(maps * 100 + dims));
  MatXf keys(maps, dims);
  for (Eigen::Index i = 0; i < keys.size(); ++i) keys.data()[i] = float(rng.normal());
  const NearestCodeSearch search(keys, kernel);
  // A rotating set of queries so the branch predictor cannot learn one answer.
  constexpr int kQueries = 64;
  std::vector<float> codes(size_t(kQueries) * dims);
  for (float& c : codes) c = float(rng.normal());
  int q = 0;
  uint64_t sum = 0;
  for (auto _ : state) {
    const NearestCode r = search.find(std::span<const float>(codes.data() + size_t(q) * dims, size_t(dims)));
    sum += r.index;
    q = (q + 1) % kQueries;
  }
  benchmark::DoNotOptimize(sum);
  state.SetLabel(toString(search.kernel()));
}

void BM_NearestCode(benchmark::State& state) { runLookup(state, CpuKernel::Auto); }
void BM_NearestCodePortable(benchmark::State& state) { runLookup(state, CpuKernel::Portable); }

}  // namespace

BENCHMARK(BM_NearestCode)->ArgsProduct({{128}, {8, 12, 16, 24, 32}})->Args({1024, 16});
BENCHMARK(BM_NearestCodePortable)->ArgsProduct({{128}, {8, 32}});

BENCHMARK_MAIN();
