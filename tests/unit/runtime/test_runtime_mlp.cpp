// Runtime, per-frame CPU side: Theta (6D rotations of the input joints), the polynomial exp behind SELU,
// and MLP inference against a plain double-precision evaluation.
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <limits>
#include <vector>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/fast_exp.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/mlp_kernel.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Distance in units in the last place between two finite floats of the same sign region.
int64_t ulpDistance(float a, float b) {
  auto key = [](float f) {
    const int32_t i = std::bit_cast<int32_t>(f);
    return i < 0 ? int64_t(INT32_MIN) - i : int64_t(i);
  };
  return std::abs(key(a) - key(b));
}

// ---- Plain double-precision reference, written for clarity, with a forward error bound. ----

double seluD(double x) {
  return x > 0 ? 1.0507009873554805 * x : 1.0507009873554805 * 1.6732632423543772 * std::expm1(x);
}

struct Reference {
  std::vector<double> y;      // Lambda
  std::vector<double> bound;  // bound on |float result - y|
};

// Standard running error analysis (Higham, "Accuracy and Stability of Numerical Algorithms", 3.1): a
// float dot product of length n with a bias has error <= gamma(n+1) * sum(|w||a| + |b|), gamma(n) =
// n u / (1 - n u), u = 2^-24; input errors pass through the weights (sum |w| e) and SELU (Lipschitz
// lambda * alpha = 1.76 on the negative side). SELU itself adds the exp error (2 ulp of a value <= 1:
// the polynomial is measured below) plus three roundings, all on values of magnitude <= 1.76, and a
// rounding relative to its result. Normalisation adds two roundings plus the reciprocal's, and
// de-normalisation two. This is a bound, not an estimate: the test fails only if a kernel computes
// something else, not because of an unlucky rounding.
Reference referenceMlp(const Mlp& mlp, const Normalisation& in, const Normalisation& out, const float* x) {
  const double u = std::ldexp(1.0, -24);
  auto gamma = [&](double n) { return n * u / (1 - n * u); };
  const int n0 = mlp.inputSize();
  std::vector<double> a(n0), e(n0);
  for (int k = 0; k < n0; ++k) {
    a[k] = (double(x[k]) - in.mean[k]) / double(in.scale[k]);
    e[k] = 3 * u * std::abs(a[k]) + 1e-30;
  }
  for (size_t l = 0; l < mlp.layers.size(); ++l) {
    const MlpLayer& L = mlp.layers[l];
    const bool hidden = l + 1 < mlp.layers.size();
    std::vector<double> z(L.weight.rows()), ez(L.weight.rows());
    for (Eigen::Index o = 0; o < L.weight.rows(); ++o) {
      double s = L.bias[o], mag = std::abs(double(L.bias[o])), prop = 0;
      for (Eigen::Index k = 0; k < L.weight.cols(); ++k) {
        s += double(L.weight(o, k)) * a[k];
        mag += std::abs(double(L.weight(o, k)) * a[k]);
        prop += std::abs(double(L.weight(o, k))) * e[k];
      }
      z[o] = s;
      ez[o] = prop + gamma(double(L.weight.cols() + 1)) * mag;
    }
    if (hidden) {
      const double lipschitz = 1.0507009873554805 * 1.6732632423543772;
      for (size_t o = 0; o < z.size(); ++o) {
        z[o] = seluD(z[o]);
        ez[o] = lipschitz * ez[o] + lipschitz * (2 * 2 * u + 3 * u) + u * std::abs(z[o]);
      }
    }
    a = z;
    e = ez;
  }
  Reference r;
  for (size_t o = 0; o < a.size(); ++o) {
    r.y.push_back(a[o] * out.scale[o] + out.mean[o]);
    r.bound.push_back(std::abs(double(out.scale[o])) * e[o] +
                      2 * u * (std::abs(a[o] * out.scale[o]) + std::abs(double(out.mean[o]))));
  }
  return r;
}

Mlp randomMlp(Rng& rng, const std::vector<int>& widths) {
  Mlp mlp;
  for (size_t l = 1; l < widths.size(); ++l) {
    MlpLayer L;
    L.weight.resize(widths[l], widths[l - 1]);
    L.bias.resize(widths[l]);
    const double sd = 1.0 / std::sqrt(double(widths[l - 1]));
    for (Eigen::Index i = 0; i < L.weight.size(); ++i) L.weight.data()[i] = float(rng.normal(0, sd));
    for (Eigen::Index i = 0; i < L.bias.size(); ++i) L.bias[i] = float(rng.normal(0, 0.3));
    mlp.layers.push_back(std::move(L));
  }
  return mlp;
}

Normalisation randomNorm(Rng& rng, int n) {
  Normalisation nrm;
  nrm.mean.resize(n);
  nrm.scale.resize(n);
  for (int i = 0; i < n; ++i) {
    nrm.mean[i] = rng.uniformf(-0.5f, 0.5f);
    nrm.scale[i] = rng.uniformf(0.2f, 3.f);
  }
  return nrm;
}

}  // namespace

// ---- Theta ----

TEST(RuntimeTheta, IdentityRotationIsFirstTwoColumnsOfTheIdentity) {
  const std::vector<Quatf> pose(3, Quatf::Identity());
  const std::vector<uint32_t> joints{2};
  ThetaReport report;
  const std::vector<float> theta = computeTheta(joints, pose, &report);
  ASSERT_EQ(theta.size(), 6u);
  const float expect[6] = {1, 0, 0, 0, 1, 0};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(theta[k], expect[k]);
  EXPECT_TRUE(report.clean());
}

TEST(RuntimeTheta, FollowsTheModelsJointOrderAndTheColumnConvention) {
  // Joint 1: 90 degrees about Z maps x -> y and y -> -x: columns (0,1,0) and (-1,0,0).
  std::vector<Quatf> pose(3, Quatf::Identity());
  pose[1] = Quatf(Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitZ()));
  const std::vector<uint32_t> joints{1, 0};  // joint 1 first
  const std::vector<float> theta = computeTheta(joints, pose);
  const float expect[12] = {0, 1, 0, -1, 0, 0, 1, 0, 0, 0, 1, 0};
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(theta[k], expect[k], 1e-6f) << k;
  // q and -q are one rotation: same Theta.
  pose[1].coeffs() = -pose[1].coeffs();
  const std::vector<float> flipped = computeTheta(joints, pose);
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(flipped[k], theta[k], 1e-6f);
}

TEST(RuntimeTheta, ReportsRenormalisedAndInvalidJointsWithTheirSlots) {
  std::vector<Quatf> pose(5, Quatf::Identity());
  pose[1] = Quatf(0, 0, 0, 3);     // non-unit: renormalised to 180 degrees about Z
  pose[3] = Quatf(kNaN, 0, 0, 0);  // invalid: identity
  pose[4] = Quatf(0, 0, 0, 0);     // invalid: identity (not even used below)
  const std::vector<uint32_t> joints{3, 1, 0};
  std::vector<ThetaJointIssue> issues;
  ThetaReport report;
  const std::vector<float> theta = computeTheta(joints, pose, &report, &issues);
  EXPECT_EQ(report.renormalised, 1u);
  EXPECT_EQ(report.invalid, 1u);  // joint 4 is not an input joint: not read, not reported
  ASSERT_EQ(issues.size(), 2u);
  EXPECT_EQ(issues[0].skeletonJoint, 3u);
  EXPECT_EQ(issues[0].inputSlot, 0u);
  EXPECT_EQ(issues[0].status, QuatStatus::Invalid);
  EXPECT_EQ(issues[1].skeletonJoint, 1u);
  EXPECT_EQ(issues[1].inputSlot, 1u);
  EXPECT_EQ(issues[1].status, QuatStatus::Renormalised);
  const float expect[18] = {1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 1, 0, 0, 0, 1, 0};
  for (int k = 0; k < 18; ++k) EXPECT_NEAR(theta[k], expect[k], 1e-6f) << k;
}

TEST(RuntimeTheta, WrongSizesThrow) {
  const std::vector<Quatf> pose(2, Quatf::Identity());
  const std::vector<uint32_t> joints{0, 2};
  EXPECT_THROW(computeTheta(joints, pose), Error);
  std::vector<float> small(5);
  EXPECT_THROW(computeTheta(std::vector<uint32_t>{0}, pose, std::span<float>(small)), Error);
}

// ---- The polynomial exp ----

TEST(RuntimeFastExp, WithinTwoUlpOfCorrectlyRoundedExpOverTheNormalRange) {
  // Dense sweep of [-87.3, 88.7] (results normal floats): 2^20 points plus exact integers and halves.
  std::vector<float> xs;
  const int n = 1 << 20;
  for (int i = 0; i <= n; ++i) xs.push_back(float(-87.3 + (88.7 + 87.3) * double(i) / n));
  for (int i = -87; i <= 88; ++i) {
    xs.push_back(float(i));
    xs.push_back(float(i) + 0.5f);
  }
  xs.push_back(-0.f);
  xs.push_back(1e-30f);
  xs.push_back(-1e-30f);
  std::vector<float> avx(xs.size());
  const bool haveAvx = cpuHasAvx2Fma();
  if (haveAvx) expArrayAvx2(xs.data(), avx.data(), xs.size());
  int64_t worstScalar = 0, worstAvx = 0;
  for (size_t i = 0; i < xs.size(); ++i) {
    const float ref = float(std::exp(double(xs[i])));  // correctly rounded but for double rounding
    worstScalar = std::max(worstScalar, ulpDistance(expApprox(xs[i]), ref));
    if (haveAvx) worstAvx = std::max(worstAvx, ulpDistance(avx[i], ref));
  }
  EXPECT_LE(worstScalar, 2);
  if (haveAvx) {
    EXPECT_LE(worstAvx, 2);
  }
  EXPECT_EQ(expApprox(0.f), 1.f);
  EXPECT_EQ(expApprox(-0.f), 1.f);
}

TEST(RuntimeFastExp, UnderflowOverflowAndNaN) {
  // Large negative inputs (what SELU sees for very negative pre-activations) go smoothly to 0 through
  // the subnormals; large positive ones overflow to +inf; NaN stays NaN.
  std::vector<float> xs{-87.5f,   -90.f, -95.f,  -100.f, -103.f, -103.9f, -104.f, -110.f, -1e4f, -1e30f,
                        -FLT_MAX, -kInf, 88.72f, 88.8f,  89.f,   100.f,   1e30f,  kInf,   kNaN};
  std::vector<float> avx(xs.size());
  const bool haveAvx = cpuHasAvx2Fma();
  if (haveAvx) expArrayAvx2(xs.data(), avx.data(), xs.size());
  const float smallestSubnormal = std::numeric_limits<float>::denorm_min();
  for (size_t i = 0; i < xs.size(); ++i) {
    const float x = xs[i];
    const float ref = float(std::exp(double(x)));
    std::vector<float> got{expApprox(x)};
    if (haveAvx) got.push_back(avx[i]);
    for (float g : got) {
      if (std::isnan(x)) {
        EXPECT_TRUE(std::isnan(g));
      } else if (std::isinf(ref)) {
        EXPECT_EQ(g, kInf) << x;
      } else if (ref < FLT_MIN) {
        EXPECT_LE(std::abs(double(g) - double(ref)), double(smallestSubnormal)) << x;  // one subnormal step
        EXPECT_GE(g, 0.f);
      } else {
        EXPECT_LE(ulpDistance(g, ref), 2) << x;
      }
    }
  }
}

TEST(RuntimeFastExp, SeluMatchesItsDefinition) {
  for (float x : {-50.f, -3.f, -1.f, -1e-3f, 0.f, 1e-3f, 1.f, 7.f}) {
    const double ref = seluD(double(x));
    EXPECT_NEAR(seluApprox(x), ref, 4e-7 * (1 + std::abs(ref))) << x;
  }
  EXPECT_EQ(seluApprox(0.f), 0.f);
  EXPECT_TRUE(std::isnan(seluApprox(kNaN)));
  EXPECT_NEAR(seluApprox(-1e30f), -1.0507009873554805 * 1.6732632423543772, 1e-6);
}

// ---- MLP ----

TEST(RuntimeMlp, HandComputedTinyNetwork) {
  // 2 -> 2 (SELU) -> 1, with normalisation on both sides. Input (3, 1), mean (1, 1), scale (2, 1):
  // normalised (1, 0). Hidden pre-activations: (1*1 - 1*0 + 0, 0.5*1 + 2*0 - 1) = (1, -0.5).
  // SELU: (lambda, lambda*alpha*(e^-0.5 - 1)). Output: 2*h0 + 1*h1 + 0.25, then *3 + 10.
  Mlp mlp;
  MlpLayer h, o;
  h.weight.resize(2, 2);
  h.weight << 1, -1, 0.5f, 2;
  h.bias.resize(2);
  h.bias << 0, -1;
  o.weight.resize(1, 2);
  o.weight << 2, 1;
  o.bias.resize(1);
  o.bias << 0.25f;
  mlp.layers = {h, o};
  Normalisation in{Eigen::Vector2f(1, 1), Eigen::Vector2f(2, 1)};
  Normalisation out{VecXf::Constant(1, 10.f), VecXf::Constant(1, 3.f)};
  const double lambda = 1.0507009873554805, alpha = 1.6732632423543772;
  const double h0 = lambda * 1.0, h1 = lambda * alpha * (std::exp(-0.5) - 1.0);
  const double expect = (2 * h0 + h1 + 0.25) * 3 + 10;  // by hand: (2.10140 - 0.69176 + 0.25) * 3 + 10
  EXPECT_NEAR(expect, 14.97894, 1e-4);                  // the hand arithmetic, to 4 decimals
  for (CpuKernel k : availableCpuKernels()) {
    const MlpEvaluator eval(mlp, in, out, 0, k);
    const float x[2] = {3, 1};
    float y = 0;
    eval.evaluate(x, std::span<float>(&y, 1));
    EXPECT_NEAR(y, expect, 2e-6 * expect) << toString(k);
    EXPECT_EQ(eval.meshComponents(), 0);
    EXPECT_EQ(eval.normalCodeDims(), 1);
  }
}

TEST(RuntimeMlp, MatchesDoubleReferenceWithinTheForwardErrorBound) {
  const uint64_t seed = test::testSeed(201);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  // The paper's network, and shapes that exercise every tile of the kernels (widths not multiples of 8
  // or 32, wider than 32, a single layer, one input).
  const std::vector<std::vector<int>> shapes{
      {32, 32, 32, 32, 32, 32, 30}, {30, 5, 13, 40, 7}, {6, 64, 64, 3}, {1, 1}, {18, 33, 9}, {12, 96, 20}};
  for (const auto& widths : shapes) {
    const Mlp mlp = randomMlp(rng, widths);
    const Normalisation in = randomNorm(rng, widths.front()), out = randomNorm(rng, widths.back());
    const size_t count = 37;
    std::vector<float> theta(count * widths.front());
    for (float& t : theta) t = rng.uniformf(-1.f, 1.f);
    std::vector<Reference> refs;
    for (size_t i = 0; i < count; ++i) refs.push_back(referenceMlp(mlp, in, out, theta.data() + i * widths.front()));
    for (CpuKernel k : availableCpuKernels()) {
      const MlpEvaluator eval(mlp, in, out, widths.back() / 2, k);
      std::vector<float> lambda(count * widths.back());
      eval.evaluateBatch(theta, lambda, count);
      double worstRatio = 0;
      for (size_t i = 0; i < count; ++i)
        for (int o = 0; o < widths.back(); ++o) {
          const double err = std::abs(double(lambda[i * widths.back() + o]) - refs[i].y[o]);
          worstRatio = std::max(worstRatio, err / refs[i].bound[o]);
        }
      RecordProperty("worst_error_over_bound", std::to_string(worstRatio));
      EXPECT_LE(worstRatio, 1.0) << toString(k) << " shape starting " << widths.front() << " -> " << widths.back();
    }
  }
}

TEST(RuntimeMlp, BatchEqualsSingleBitwise) {
  Rng rng(test::testSeed(202));
  const Mlp mlp = randomMlp(rng, {24, 32, 32, 32, 32, 32, 26});
  const Normalisation in = randomNorm(rng, 24), out = randomNorm(rng, 26);
  const size_t count = 300;  // crosses the evaluator's 128-instance chunks, odd tail
  std::vector<float> theta(count * 24);
  for (float& t : theta) t = rng.uniformf(-1.f, 1.f);
  for (CpuKernel k : availableCpuKernels()) {
    const MlpEvaluator eval(mlp, in, out, 16, k);
    std::vector<float> batch(count * 26), mesh(count * 16), code(count * 10);
    eval.evaluateBatch(theta, batch, count);
    eval.evaluateBatchSplit(theta, mesh, code, count);
    for (size_t i = 0; i < count; ++i) {
      float single[26];
      eval.evaluate(std::span<const float>(theta.data() + i * 24, 24), single);
      for (int o = 0; o < 26; ++o) {
        ASSERT_EQ(std::bit_cast<uint32_t>(single[o]), std::bit_cast<uint32_t>(batch[i * 26 + o]))
            << toString(k) << " instance " << i << " output " << o;
        const float split = o < 16 ? mesh[i * 16 + o] : code[i * 10 + o - 16];
        ASSERT_EQ(std::bit_cast<uint32_t>(split), std::bit_cast<uint32_t>(batch[i * 26 + o]));
      }
      const std::span<const float> lam(batch.data() + i * 26, 26);
      EXPECT_EQ(eval.meshWeightsOf(lam).data(), lam.data());
      EXPECT_EQ(eval.normalCodeOf(lam).data(), lam.data() + 16);
      EXPECT_EQ(eval.normalCodeOf(lam).size(), 10u);
    }
  }
}

TEST(RuntimeMlp, BuildsFromAModelAndRejectsBadShapes) {
  Rng rng(test::testSeed(203));
  const Model model = test::makeRandomModel(rng);
  const MlpEvaluator eval(model);
  EXPECT_EQ(eval.inputSize(), model.thetaSize());
  EXPECT_EQ(eval.outputSize(), model.lambdaSize());
  EXPECT_EQ(eval.meshComponents(), model.meshComponents());
  EXPECT_NE(eval.kernel(), CpuKernel::Auto);
  std::vector<float> theta(model.thetaSize()), lambda(model.lambdaSize() + 1);
  EXPECT_THROW(eval.evaluate(theta, lambda), Error);
  EXPECT_THROW(eval.evaluateBatch(theta, std::span<float>(lambda).first(model.lambdaSize()), 2), Error);

  Mlp broken = model.mlp;
  broken.layers[1].weight.resize(3, 3);
  EXPECT_THROW(MlpEvaluator(broken, model.inputNorm, model.outputNorm, model.meshComponents()), Error);
  Normalisation zeroScale = model.outputNorm;
  zeroScale.scale[0] = 0.f;
  EXPECT_THROW(MlpEvaluator(model.mlp, model.inputNorm, zeroScale, model.meshComponents()), Error);
  EXPECT_THROW(MlpEvaluator(model.mlp, model.inputNorm, model.outputNorm, model.lambdaSize() + 1), Error);
  if (!cpuHasAvx2Fma()) {
    EXPECT_THROW(MlpEvaluator(model, CpuKernel::Avx2Fma), Error);
  }
}
