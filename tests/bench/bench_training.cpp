// The paper's regressor (Theta of 5 joints = 30 inputs, 5 hidden layers of 32, SELU, ~30 outputs) on
// 700 samples, trained to early stopping with the bake's default options. Goal: <= 60 s (paper: 5 min).
// The data: 6D rotations of random joint rotations, outputs a smooth nonlinear function of them.
#include <benchmark/benchmark.h>

#include <cmath>

#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

static void makeData(MatXf& x, MatXf& y, int samples, int outputs) {
  Rng rng(77);
  x.resize(30, samples);
  y.resize(outputs, samples);
  MatXf mix(outputs, 30);
  for (Eigen::Index i = 0; i < mix.size(); ++i) mix.data()[i] = float(rng.normal());
  for (int s = 0; s < samples; ++s) {
    for (int j = 0; j < 5; ++j) {
      const Vec3f axis = Vec3f(float(rng.normal()), float(rng.normal()), float(rng.normal())).normalized();
      const Mat3f r = Eigen::AngleAxisf(float(rng.uniform(0, 1.0)), axis).toRotationMatrix();
      x.block<3, 1>(6 * j, s) = r.col(0);
      x.block<3, 1>(6 * j + 3, s) = r.col(1);
    }
    y.col(s) = (0.5f * mix * x.col(s)).array().sin().matrix();
  }
}

static void BM_TrainPaperMlp700(benchmark::State& state) {
  MatXf x, y;
  makeData(x, y, 700, 28);
  MlpTrainOptions o;  // defaults: 5 x 32 SELU, Adam, early stopping
  double val = 0, epochs = 0, seconds = 0;
  for (auto _ : state) {
    const MlpTrainResult r = trainMlp(x, y, o);
    val = r.bestValidationLoss, epochs = r.epochsRun, seconds = r.seconds;
  }
  state.counters["epochs"] = epochs;
  state.counters["best_val_loss"] = val;
  state.counters["train_seconds"] = seconds;
  state.counters["ms_per_epoch"] = 1000.0 * seconds / std::max(1.0, epochs);
}
BENCHMARK(BM_TrainPaperMlp700)->Unit(benchmark::kSecond)->Iterations(1);

BENCHMARK_MAIN();
