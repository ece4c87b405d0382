// Stability of the per-frame CPU side: degenerate quaternions, extreme network inputs and weights,
// zero-variance normalisation, hostile normal codes and frame times. Finite data in must give finite data
// out and valid indices, whatever the values; NaN must never appear unless it was given.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <vector>

#include "support/random_model.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/mlp_kernel.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

bool allFinite(std::span<const float> v) {
  for (float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// Values a hostile or broken animation source can produce.
std::vector<float> nastyFloats() {
  return {0.f,   -0.f,    1.f,      -1.f, 1e-30f, -1e-30f, std::numeric_limits<float>::denorm_min(), 1e20f, -1e20f,
          1e30f, FLT_MAX, -FLT_MAX, kInf, -kInf,  kNaN};
}

}  // namespace

TEST(RuntimeStability, DegenerateQuaternionsGiveValidRotationsInTheta) {
  const std::vector<float> v = nastyFloats();
  std::vector<Quatf> pose;
  for (size_t a = 0; a < v.size(); ++a)
    for (size_t b = 0; b < v.size(); ++b) {
      pose.emplace_back(v[a], v[b], v[(a + b) % v.size()], v[(a * 7 + b) % v.size()]);
      pose.emplace_back(v[a], v[b], v[a], v[b]);
    }
  std::vector<uint32_t> joints(pose.size());
  for (uint32_t j = 0; j < joints.size(); ++j) joints[j] = j;
  ThetaReport report;
  std::vector<ThetaJointIssue> issues;
  const std::vector<float> theta = computeTheta(joints, pose, &report, &issues);
  ASSERT_TRUE(allFinite(theta));
  EXPECT_EQ(issues.size(), size_t(report.invalid + report.renormalised));
  EXPECT_GT(report.invalid, 0u);
  EXPECT_GT(report.renormalised, 0u);
  for (size_t j = 0; j < joints.size(); ++j) {
    // Each 6D vector is two orthonormal columns: a real rotation, whatever came in.
    const Eigen::Map<const Vec3f> c0(theta.data() + 6 * j), c1(theta.data() + 6 * j + 3);
    EXPECT_NEAR(c0.norm(), 1.f, 1e-5f) << j;
    EXPECT_NEAR(c1.norm(), 1.f, 1e-5f) << j;
    EXPECT_NEAR(c0.dot(c1), 0.f, 1e-5f) << j;
  }
}

TEST(RuntimeStability, ExtremeNetworkInputsAndWeightsStayFinite) {
  Rng rng(test::testSeed(501));
  // Big weights (1e3..1e6 scale) compound over six layers to far beyond float range without the
  // evaluator's activation bounds.
  for (double weightScale : {1.0, 1e3, 1e6, 1e12}) {
    Mlp mlp;
    int prev = 12;
    for (int l = 0; l < 6; ++l) {
      const int width = l < 5 ? 32 : 9;
      MlpLayer L;
      L.weight.resize(width, prev);
      L.bias.resize(width);
      for (Eigen::Index i = 0; i < L.weight.size(); ++i) L.weight.data()[i] = float(rng.normal(0, weightScale));
      for (Eigen::Index i = 0; i < L.bias.size(); ++i) L.bias[i] = float(rng.normal(0, weightScale));
      mlp.layers.push_back(std::move(L));
      prev = width;
    }
    Normalisation in{VecXf::Zero(12), VecXf::Ones(12)};
    in.scale[3] = std::numeric_limits<float>::denorm_min();  // a zero-variance input, as a bake might store it
    in.scale[4] = 1e-30f;
    Normalisation out{VecXf::Constant(9, 0.5f), VecXf::Constant(9, 1e30f)};
    for (CpuKernel k : availableCpuKernels()) {
      const MlpEvaluator eval(mlp, in, out, 4, k);
      const std::vector<float> v = nastyFloats();
      std::vector<float> theta;
      size_t count = 0;
      for (float a : v) {
        if (!std::isfinite(a)) continue;
        for (int i = 0; i < 12; ++i) theta.push_back(i % 2 ? a : -a * 0.5f);
        ++count;
      }
      std::vector<float> lambda(count * 9);
      eval.evaluateBatch(theta, lambda, count);
      EXPECT_TRUE(allFinite(lambda)) << "weights ~" << weightScale << ", " << toString(k);
    }
  }
}

TEST(RuntimeStability, ZeroVarianceOutputScaleGivesTheMean) {
  Rng rng(test::testSeed(502));
  const Model model = test::makeRandomModel(rng);
  Normalisation out = model.outputNorm;
  out.scale.setConstant(std::numeric_limits<float>::denorm_min());  // positive, so a valid model
  out.mean.setLinSpaced(out.mean.size(), -2.f, 3.f);
  for (CpuKernel k : availableCpuKernels()) {
    const MlpEvaluator eval(model.mlp, model.inputNorm, out, model.meshComponents(), k);
    std::vector<float> theta(model.thetaSize(), 0.3f), lambda(model.lambdaSize());
    eval.evaluate(theta, lambda);
    ASSERT_TRUE(allFinite(lambda));
    // The network's output (bounded) times the smallest subnormal is below half an ulp of the mean
    // unless the mean is 0, where the product itself is a subnormal.
    for (int o = 0; o < model.lambdaSize(); ++o) EXPECT_NEAR(lambda[o], out.mean[o], 1e-30f) << o;
  }
}

TEST(RuntimeStability, NaNInputIsNotHidden) {
  Rng rng(test::testSeed(503));
  const Model model = test::makeRandomModel(rng);
  for (CpuKernel k : availableCpuKernels()) {
    const MlpEvaluator eval(model, k);
    std::vector<float> theta(model.thetaSize(), 0.1f), lambda(model.lambdaSize());
    theta[2] = kNaN;
    eval.evaluate(theta, lambda);
    // Every output depends on every input through dense layers: all NaN.
    for (float y : lambda) EXPECT_TRUE(std::isnan(y)) << toString(k);
  }
}

TEST(RuntimeStability, FrameEvaluatorSurvivesHostileFrames) {
  const uint64_t seed = test::testSeed(504);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.normalMaps = 9;
  spec.codeDims = 4;
  Model model = test::makeRandomModel(rng, spec);
  model.temporalFilter.timeConstantSeconds = 0.f;  // also the no-filtering edge
  const uint32_t n = 5, j = uint32_t(model.skeleton.size());
  for (float timeConstant : {0.f, 0.1f, 1e30f}) {
    model.temporalFilter.timeConstantSeconds = timeConstant;
    FrameEvaluator frame(model, n);
    const std::vector<float> v = nastyFloats();
    for (int f = 0; f < 60; ++f) {
      std::vector<Quatf> rotations(size_t(n) * j);
      for (Quatf& q : rotations)
        q = Quatf(v[rng.below(v.size())], v[rng.below(v.size())], v[rng.below(v.size())], v[rng.below(v.size())]);
      std::vector<float> dts(n);
      for (float& d : dts) d = rng.below(3) ? rng.uniformf(0.f, 0.1f) : v[rng.below(v.size())];
      const FrameOutput& out = frame.evaluate(rotations, dts);
      ASSERT_TRUE(allFinite(out.meshWeights)) << "frame " << f;
      ASSERT_TRUE(allFinite(out.normalCodes)) << "frame " << f;
      EXPECT_TRUE(out.nonFiniteCode.empty());  // sanitised Theta and bounded network: codes stay finite
      for (uint32_t c = 0; c < n; ++c) {
        EXPECT_LT(out.mapIndex[c], model.normalMaps.mapCount());
        EXPECT_GE(out.blendAlpha[c], 0.f);
        EXPECT_LE(out.blendAlpha[c], 1.f);
      }
    }
  }
}

TEST(RuntimeStability, LookupWithExtremeCodes) {
  MatXf keys(6, 3);
  keys << 0, 0, 0, 1e30f, 0, 0, -1e30f, 0, 0, 0, FLT_MAX, 0, 0, 0, -FLT_MAX, 1, 1, 1;
  for (CpuKernel k : availableCpuKernels()) {
    const NearestCodeSearch search(keys, k);
    for (float a : nastyFloats())
      for (float b : nastyFloats()) {
        const float code[3] = {a, b, -a};
        const NearestCode r = search.find(code, 5);
        EXPECT_LT(r.index, 6u);
        EXPECT_EQ(r.found, std::isfinite(a) && std::isfinite(b));
      }
  }
}
