// MLP training: analytic gradients match finite differences for every activation; training fits a
// smooth function of rotations, is deterministic for a seed, and early-stops on the best epoch.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "support/random_model.hpp"
#include "swish/bake/training/mlp_network.hpp"
#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

TEST(BakeMlp, GradientsMatchFiniteDifferences) {
  for (Activation act : {Activation::Selu, Activation::Relu, Activation::Tanh}) {
    SCOPED_TRACE(activationName(act));
    Rng rng(test::testSeed(401));
    MlpNetwork<double> net({5, 7, 6, 3}, act, rng);
    for (auto& b : net.biases)
      for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = 0.3 * rng.normal();
    Eigen::MatrixXd x(5, 4), y(3, 4);
    for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = rng.normal();
    for (Eigen::Index i = 0; i < y.size(); ++i) y.data()[i] = rng.normal();
    Eigen::VectorXd w(3);
    w << 1.0, 0.5, 2.0;
    std::vector<Eigen::MatrixXd> gW;
    std::vector<Eigen::VectorXd> gB;
    net.lossAndGradient(x, y, w, gW, gB);
    const double h = 1e-6;
    for (int l = 0; l < net.layers(); ++l) {
      for (Eigen::Index i = 0; i < net.weights[size_t(l)].size(); ++i) {
        MlpNetwork<double> p = net, m = net;
        p.weights[size_t(l)].data()[i] += h;
        m.weights[size_t(l)].data()[i] -= h;
        const double fd = (p.loss(x, y, w) - m.loss(x, y, w)) / (2 * h);
        // ReLU kinks make finite differences unreliable only exactly at 0, which random data avoids.
        EXPECT_NEAR(gW[size_t(l)].data()[i], fd, 1e-6 + 1e-5 * std::abs(fd)) << "layer " << l << " weight " << i;
      }
      for (Eigen::Index i = 0; i < net.biases[size_t(l)].size(); ++i) {
        MlpNetwork<double> p = net, m = net;
        p.biases[size_t(l)][i] += h;
        m.biases[size_t(l)][i] -= h;
        const double fd = (p.loss(x, y, w) - m.loss(x, y, w)) / (2 * h);
        EXPECT_NEAR(gB[size_t(l)][i], fd, 1e-6 + 1e-5 * std::abs(fd)) << "layer " << l << " bias " << i;
      }
    }
  }
}

TEST(BakeMlp, LeCunInitialisationHasUnitFanInVariance) {
  Rng rng(test::testSeed(402));
  MlpNetwork<double> net({400, 300, 2}, Activation::Selu, rng);
  const double var = net.weights[0].cwiseAbs2().mean();
  EXPECT_NEAR(var * 400.0, 1.0, 0.03);
  EXPECT_EQ(net.biases[0].cwiseAbs().maxCoeff(), 0.0);
}

namespace {
// Theta: two joints' 6D vectors from random rotations; Lambda: a smooth nonlinear function of them.
void makeRegression(Rng& rng, int n, MatXf& x, MatXf& y) {
  x.resize(12, n);
  y.resize(4, n);
  for (int s = 0; s < n; ++s) {
    for (int j = 0; j < 2; ++j) {
      const Vec3f axis = Vec3f(float(rng.normal()), float(rng.normal()), float(rng.normal())).normalized();
      const Mat3f r = Eigen::AngleAxisf(float(rng.uniform(0, 1.2)), axis).toRotationMatrix();
      x.block<3, 1>(6 * j, s) = r.col(0);
      x.block<3, 1>(6 * j + 3, s) = r.col(1);
    }
    const auto c = x.col(s);
    y(0, s) = 10.f * c[1] + 3.f * c[2] * c[6];
    y(1, s) = std::sin(2.f * c[4]) - c[9];
    y(2, s) = 0.01f * c[7] * c[8];
    y(3, s) = 5.f + c[0] * c[0];
  }
}

// Two hidden layers of 32, seed 11, every one of `epochs` epochs run (patience as long), so that two
// runs with different regularisers end at the same step count.
MlpTrainOptions fixedRun(int epochs) {
  MlpTrainOptions o;
  o.hiddenLayers = 2;
  o.hiddenWidth = 32;
  o.maxEpochs = epochs;
  o.patience = epochs;
  o.seed = 11;
  return o;
}
}  // namespace

TEST(BakeMlp, TrainsASmoothMapDeterministicallyAndKeepsTheBestEpoch) {
  const uint64_t seed = test::testSeed(403);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  MatXf x, y;
  makeRegression(rng, 300, x, y);
  MlpTrainOptions o;
  o.hiddenLayers = 2;
  o.hiddenWidth = 32;
  o.maxEpochs = 150;
  o.patience = 40;
  o.seed = 11;
  const MlpTrainResult a = trainMlp(x, y, o);
  const MlpTrainResult b = trainMlp(x, y, o);
  ASSERT_EQ(a.mlp.layers.size(), 3u);
  EXPECT_EQ(a.mlp.layers[0].weight, b.mlp.layers[0].weight);
  EXPECT_EQ(a.bestEpoch, b.bestEpoch);
  EXPECT_EQ(a.validationSamples.size(), 30u);
  // Best epoch is the minimum of the validation curve.
  double minVal = 1e30;
  for (const auto& e : a.curve) minVal = std::min(minVal, e.validationLoss);
  EXPECT_DOUBLE_EQ(a.bestValidationLoss, minVal);
  EXPECT_LT(a.bestValidationLoss, 0.05);  // standardised MSE: much better than the mean (1.0)
  EXPECT_LT(a.curve.back().trainLoss, a.curve.front().trainLoss * 0.2);
  // evaluateMlp undoes the standardisation: predictions land in the original units.
  double err = 0.0, spread = 0.0;
  for (uint32_t s : a.validationSamples) {
    const VecXf pred = evaluateMlp(a.mlp, a.inputNorm, a.outputNorm, x.col(s));
    err += (pred - y.col(s)).squaredNorm();
    spread += (y.col(s) - a.outputNorm.mean).squaredNorm();
  }
  EXPECT_LT(err, 0.1 * spread);
}

// Decoupled weight decay shrinks the weight matrices the network ends with and still fits the map.
TEST(BakeMlp, WeightDecayShrinksTheWeights) {
  const uint64_t seed = test::testSeed(404);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  MatXf x, y;
  makeRegression(rng, 300, x, y);
  MlpTrainOptions o = fixedRun(100);
  const MlpTrainResult plain = trainMlp(x, y, o);
  o.weightDecay = 1.0;  // lr 2e-3: 0.2 % per step
  const MlpTrainResult decayed = trainMlp(x, y, o);
  double plainNorm = 0.0, decayedNorm = 0.0;
  for (size_t l = 0; l < plain.mlp.layers.size(); ++l) {
    plainNorm += plain.mlp.layers[l].weight.squaredNorm();
    decayedNorm += decayed.mlp.layers[l].weight.squaredNorm();
  }
  EXPECT_LT(decayedNorm, 0.8 * plainNorm) << decayedNorm << " vs " << plainNorm << ", loss " << plain.bestValidationLoss
                                          << " -> " << decayed.bestValidationLoss;
  EXPECT_LT(decayed.bestValidationLoss, 0.2);  // standardised MSE: still far better than the mean (1.0)
  o.weightDecay = -1.0;
  EXPECT_THROW(trainMlp(x, y, o), Error);
  o.weightDecay = 1.0 / o.learningRate;
  EXPECT_THROW(trainMlp(x, y, o), Error);
}

// Input noise perturbs the training batches only: deterministic for a seed, a different network
// from the noiseless one, and one that still fits the map.
TEST(BakeMlp, InputNoiseIsSeededAndStillFits) {
  const uint64_t seed = test::testSeed(405);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  MatXf x, y;
  makeRegression(rng, 300, x, y);
  MlpTrainOptions o = fixedRun(100);
  const MlpTrainResult plain = trainMlp(x, y, o);
  o.inputNoise = 0.05;
  const MlpTrainResult a = trainMlp(x, y, o), b = trainMlp(x, y, o);
  EXPECT_EQ(a.mlp.layers[0].weight, b.mlp.layers[0].weight);
  EXPECT_NE(a.mlp.layers[0].weight, plain.mlp.layers[0].weight);
  EXPECT_EQ(a.validationSamples, plain.validationSamples);  // the split does not depend on the noise
  EXPECT_LT(a.bestValidationLoss, 0.2);
  o.inputNoise = -0.1;
  EXPECT_THROW(trainMlp(x, y, o), Error);
}

TEST(BakeMlp, SeededSplitNeverHoldsAPinnedIndex) {
  // Without pins: the plain Fisher-Yates draw (the split bakes made before pins existed).
  Rng a(test::testSeed(21)), b(test::testSeed(21));
  const IndexSplit plain = seededSplit(40, 6, a);
  std::vector<uint32_t> order(40);
  for (uint32_t i = 0; i < 40; ++i) order[i] = i;
  for (size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[b.below(i + 1)]);
  std::vector<uint32_t> held(order.begin(), order.begin() + 6);
  std::sort(held.begin(), held.end());
  EXPECT_EQ(plain.held, held);
  EXPECT_EQ(plain.kept.size(), 34u);

  for (uint64_t seed = 0; seed < 50; ++seed) {
    Rng r(seed);
    const std::vector<uint32_t> pins{3, 39};
    const IndexSplit s = seededSplit(40, 10, r, pins);
    ASSERT_EQ(s.held.size(), 10u);
    ASSERT_EQ(s.kept.size(), 30u);
    for (uint32_t p : pins) {
      EXPECT_FALSE(std::binary_search(s.held.begin(), s.held.end(), p)) << "seed " << seed;
      EXPECT_TRUE(std::binary_search(s.kept.begin(), s.kept.end(), p)) << "seed " << seed;
    }
    EXPECT_TRUE(std::is_sorted(s.held.begin(), s.held.end()));
    EXPECT_TRUE(std::is_sorted(s.kept.begin(), s.kept.end()));
  }
  Rng r(1);
  EXPECT_EQ(seededSplit(3, 5, r, std::vector<uint32_t>{0, 1}).held, std::vector<uint32_t>{2});  // at most n - pinned
}

TEST(BakeMlp, KeyedSplitHoldsTheSamePosesWhenOthersComeAndGo) {
  // Two bakes of one recipe: the second kept two poses the first lost and lost two it kept (ids as
  // part 1 numbers its thinned poses). Each key's side depends on the key and the seed alone, so of
  // the 196 ids both have, the held sets differ at most by what the 4 changed ids displaced at the
  // boundary.
  std::vector<uint64_t> a, b;
  for (uint64_t id = 0; id < 200; ++id) {
    if (id != 17 && id != 140) a.push_back(id);
    if (id != 33 && id != 171) b.push_back(id);
  }
  const uint64_t seed = test::testSeed(22);
  Rng ra(seed), rb(seed);
  const IndexSplit sa = keyedSplit(a, 20, ra), sb = keyedSplit(b, 20, rb);
  ASSERT_EQ(sa.held.size(), 20u);
  ASSERT_EQ(sb.held.size(), 20u);
  EXPECT_EQ(sa.kept.size(), 178u);
  std::set<uint64_t> heldA, heldB;
  for (uint32_t i : sa.held) heldA.insert(a[i]);
  for (uint32_t i : sb.held) heldB.insert(b[i]);
  const std::set<uint64_t> changed{17, 140, 33, 171};
  size_t onlyOne = 0;
  for (uint64_t id = 0; id < 200; ++id)
    if (!changed.count(id) && heldA.count(id) != heldB.count(id)) ++onlyOne;
  EXPECT_LE(onlyOne, 4u);
  // A shuffled index split of the same two lists shares about a tenth of its held poses.
  Rng qa(seed), qb(seed);
  const IndexSplit pa = seededSplit(a.size(), 20, qa), pb = seededSplit(b.size(), 20, qb);
  size_t shuffledOnlyOne = 0;
  std::set<uint64_t> ha, hb;
  for (uint32_t i : pa.held) ha.insert(a[i]);
  for (uint32_t i : pb.held) hb.insert(b[i]);
  for (uint64_t id = 0; id < 200; ++id)
    if (!changed.count(id) && ha.count(id) != hb.count(id)) ++shuffledOnlyOne;
  EXPECT_GT(shuffledOnlyOne, onlyOne);

  // Deterministic for a seed, another seed holds other poses, pins are never held.
  Rng r1(seed), r2(seed), r3(seed + 1);
  EXPECT_EQ(keyedSplit(a, 20, r1).held, sa.held);
  EXPECT_NE(keyedSplit(a, 20, r3).held, sa.held);
  const std::vector<uint32_t> pins{sa.held.front(), sa.held.back()};
  const IndexSplit pinnedSplit = keyedSplit(a, 20, r2, pins);
  ASSERT_EQ(pinnedSplit.held.size(), 20u);
  for (uint32_t p : pins) EXPECT_FALSE(std::binary_search(pinnedSplit.held.begin(), pinnedSplit.held.end(), p));
  EXPECT_TRUE(std::is_sorted(pinnedSplit.kept.begin(), pinnedSplit.kept.end()));
  EXPECT_EQ(pinnedSplit.kept.size(), 178u);
}

namespace {

// 50 samples of a small smooth map (3 inputs, 2 outputs) for the split tests.
void smallRegression(uint64_t seed, MatXf& x, MatXf& y) {
  Rng rng(seed);
  x.resize(3, 50), y.resize(2, 50);
  for (int i = 0; i < 50; ++i) {
    x.col(i) << float(rng.normal()), float(rng.normal()), float(rng.normal());
    y.col(i) << x(0, i) + x(1, i), x(2, i) * x(0, i);
  }
}

}  // namespace

TEST(BakeMlp, AlwaysTrainSamplesAreNeverValidated) {
  MatXf x, y;
  smallRegression(test::testSeed(22), x, y);
  MlpTrainOptions o;
  o.hiddenLayers = 1, o.hiddenWidth = 8, o.maxEpochs = 5, o.validationFraction = 0.3;
  o.alwaysTrain = {0, 17, 49};
  const MlpTrainResult r = trainMlp(x, y, o);
  EXPECT_EQ(r.validationSamples.size(), 15u);
  for (uint32_t p : o.alwaysTrain) {
    EXPECT_FALSE(std::binary_search(r.validationSamples.begin(), r.validationSamples.end(), p));
    EXPECT_TRUE(std::binary_search(r.trainingSamples.begin(), r.trainingSamples.end(), p));
  }
  o.alwaysTrain = {50};
  EXPECT_THROW(trainMlp(x, y, o), Error);
}

TEST(BakeMlp, SampleKeysChooseTheValidationSamples) {
  MatXf x, y;
  smallRegression(test::testSeed(23), x, y);
  MlpTrainOptions o;
  o.hiddenLayers = 1, o.hiddenWidth = 8, o.maxEpochs = 3, o.validationFraction = 0.2, o.seed = 9;
  for (uint64_t i = 0; i < 50; ++i) o.sampleKeys.push_back(1000 + 7 * i);  // pose ids, not columns
  o.alwaysTrain = {4};
  const MlpTrainResult r = trainMlp(x, y, o);
  Rng same(o.seed);
  EXPECT_EQ(r.validationSamples, keyedSplit(o.sampleKeys, 10, same, o.alwaysTrain).held);
  o.sampleKeys.pop_back();
  EXPECT_THROW(trainMlp(x, y, o), Error);  // one key per sample
}

TEST(BakeMlp, ConstantInputsAndOutputsStayFinite) {
  MatXf x = MatXf::Random(6, 40), y(2, 40);
  x.row(2).setConstant(0.5f);  // a joint coordinate that never changes
  y.row(0) = x.row(0) * 2.f;
  y.row(1).setConstant(3.f);  // an output that never changes
  MlpTrainOptions o;
  o.hiddenLayers = 1;
  o.maxEpochs = 20;
  const MlpTrainResult r = trainMlp(x, y, o);
  EXPECT_FLOAT_EQ(r.inputNorm.scale[2], 1.f);
  EXPECT_FLOAT_EQ(r.outputNorm.scale[1], 1.f);
  EXPECT_TRUE(evaluateMlp(r.mlp, r.inputNorm, r.outputNorm, x.col(0)).allFinite());
}

TEST(BakeMlp, BadInputIsAnError) {
  MlpTrainOptions o;
  EXPECT_THROW(trainMlp(MatXf::Ones(3, 1), MatXf::Ones(2, 1), o), Error);  // one sample
  EXPECT_THROW(trainMlp(MatXf::Ones(3, 5), MatXf::Ones(2, 4), o), Error);  // count mismatch
  MatXf bad = MatXf::Ones(3, 5);
  bad(0, 0) = std::numeric_limits<float>::infinity();
  EXPECT_THROW(trainMlp(bad, MatXf::Ones(2, 5), o), Error);
  o.validationFraction = 1.0;
  EXPECT_THROW(trainMlp(MatXf::Ones(3, 5), MatXf::Ones(2, 5), o), Error);
  EXPECT_THROW(activationFromName("gelu"), Error);
}
