// MLP inference on one core: the paper's network, 32 -> 5 x 32 SELU -> 30, batch of 22 (a Madden team on
// the field) and batch of 1. Goal: <= 0.5 us per instance (paper's console figure: 20 us; arithmetic floor
// of 6,080 multiply-adds at 16 per cycle: about 0.11 us). The per-instance time is the counter
// "us_per_instance" (a rate counter inverted: seconds per instance, shown in us).
//
//   build-*/tests/bench_mlp --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "support/paths.hpp"
#include "swish/core/rng.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/novelty_guard.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

struct PaperNetwork {
  Mlp mlp;
  Normalisation in, out;
  static constexpr int kInputs = 32, kHidden = 32, kHiddenLayers = 5, kOutputs = 30, kMeshComponents = 20;

  PaperNetwork() {
    Rng rng(2021);
    int prev = kInputs;
    for (int l = 0; l <= kHiddenLayers; ++l) {
      const int width = l < kHiddenLayers ? kHidden : kOutputs;
      MlpLayer L;
      L.weight.resize(width, prev);
      L.bias.resize(width);
      const double sd = 1.0 / std::sqrt(double(prev));  // LeCun normal, as SELU training would give
      for (Eigen::Index i = 0; i < L.weight.size(); ++i) L.weight.data()[i] = float(rng.normal(0, sd));
      for (Eigen::Index i = 0; i < L.bias.size(); ++i) L.bias[i] = float(rng.normal(0, 0.1));
      mlp.layers.push_back(std::move(L));
      prev = width;
    }
    in.mean = VecXf::Constant(kInputs, 0.1f);
    in.scale = VecXf::Constant(kInputs, 0.5f);
    out.mean = VecXf::Constant(kOutputs, 0.2f);
    out.scale = VecXf::Constant(kOutputs, 2.f);
  }
};

// Times `eval` on a batch of state.range(0) random Theta vectors (entries in [-1, 1], the range of 6D
// rotation entries) drawn from `seed`.
void timeBatches(benchmark::State& state, const MlpEvaluator& eval, uint64_t seed, const std::string& label) {
  const size_t batch = size_t(state.range(0));
  Rng rng(seed);
  std::vector<float> theta(batch * size_t(eval.inputSize())), lambda(batch * size_t(eval.outputSize()));
  for (float& t : theta) t = rng.uniformf(-1.f, 1.f);
  for (auto _ : state) {
    eval.evaluateBatch(theta, lambda, batch);
    benchmark::DoNotOptimize(lambda.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(label);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(batch));
  // kIsRate|kInvert turns instances per second into seconds per instance.
  state.counters["time_per_instance"] = benchmark::Counter(double(state.iterations()) * double(batch),
                                                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void runMlp(benchmark::State& state, CpuKernel kernel) {
  static const PaperNetwork net;
  const MlpEvaluator eval(net.mlp, net.in, net.out, PaperNetwork::kMeshComponents, kernel);
  timeBatches(state, eval, 7, toString(eval.kernel()));
}

void BM_MlpAuto(benchmark::State& state) { runMlp(state, CpuKernel::Auto); }
void BM_MlpPortable(benchmark::State& state) { runMlp(state, CpuKernel::Portable); }

// The committed default model's own network (assets/default/bake.json says its shape: its recipe
// may be wider than the paper's); the label gives the layer widths.
void BM_MlpDefaultModel(benchmark::State& state) {
  const std::filesystem::path file = test::sourceDir() / "assets/default/default.swish";
  if (!std::filesystem::exists(file)) {
    state.SkipWithError("no committed default model");
    return;
  }
  static const Model model = loadModel(file);
  const MlpEvaluator eval(model, CpuKernel::Auto);
  std::string shape = std::to_string(eval.inputSize());
  for (const auto& l : model.mlp.layers) shape.append("-").append(std::to_string(l.weight.rows()));
  timeBatches(state, eval, 11, std::string(toString(eval.kernel())) + " " + shape);
}

// The novelty guard's measure and clamp (runtime/novelty_guard.hpp) beside the default model's MLP, as
// FrameEvaluator runs them: the bound is MLP + novelty no more than 10 % above the MLP alone
// (compare BM_MlpDefaultModel at the same batch). The committed model may predate the guard (format
// 1.2): then a guard of 128 centres (the bake's default count) drawn from random inputs stands in;
// the cost depends only on the centre count and Theta's size. Arg(1) 0: the MLP alone, 1: MLP + guard.
void BM_MlpDefaultModelWithNovelty(benchmark::State& state) {
  const std::filesystem::path file = test::sourceDir() / "assets/default/default.swish";
  if (!std::filesystem::exists(file)) {
    state.SkipWithError("no committed default model");
    return;
  }
  static const Model model = [&] {
    Model m = loadModel(file);
    if (m.noveltyGuard.empty()) {
      Rng rng(5);
      NoveltyGuard& g = m.noveltyGuard;
      g.centres.resize(128, m.thetaSize());
      for (Eigen::Index i = 0; i < g.centres.size(); ++i) g.centres.data()[i] = float(rng.normal(0, 1));
      g.weightMin = VecXf::Constant(m.meshComponents(), -1.f);
      g.weightMax = VecXf::Constant(m.meshComponents(), 1.f);
      g.blendStart = 2.f, g.blendEnd = 4.f;
    }
    return m;
  }();
  const MlpEvaluator eval(model, CpuKernel::Auto);
  const NoveltyGuardEvaluator guard(model);
  const bool withGuard = state.range(1) != 0;
  const size_t batch = size_t(state.range(0)), K = size_t(model.meshComponents());
  Rng rng(11);
  std::vector<float> theta(batch * size_t(eval.inputSize())), weights(batch * K),
      codes(batch * size_t(eval.normalCodeDims())), novelty(batch);
  for (float& t : theta) t = rng.uniformf(-1.f, 1.f);
  for (auto _ : state) {
    eval.evaluateBatchSplit(theta, weights, codes, uint32_t(batch));
    if (withGuard) {
      guard.measure(theta, uint32_t(batch), novelty);
      for (size_t c = 0; c < batch; ++c) guard.apply(novelty[c], std::span<float>(weights.data() + c * K, K));
    }
    benchmark::DoNotOptimize(weights.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string(withGuard ? "MLP + novelty guard, " : "MLP alone, ") +
                 std::to_string(guard.guard().centres.rows()) + " centres");
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(batch));
  state.counters["time_per_instance"] = benchmark::Counter(double(state.iterations()) * double(batch),
                                                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_MlpDefaultModelWithNovelty)->Args({22, 0})->Args({22, 1})->Args({1, 0})->Args({1, 1});
BENCHMARK(BM_MlpAuto)->Arg(22)->Arg(1)->Arg(256);
BENCHMARK(BM_MlpPortable)->Arg(22)->Arg(1);
BENCHMARK(BM_MlpDefaultModel)->Arg(22)->Arg(1);

BENCHMARK_MAIN();
