// The run-time novelty guard (runtime/novelty_guard.hpp): its measure against a brute-force distance in
// double, the clamp and blend it applies, the frame evaluator's use of it (on, off, absent), and the
// bake's fit (bake/training/novelty_guard_fit.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "support/random_model.hpp"
#include "swish/bake/training/novelty_guard_fit.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/novelty_guard.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

Model guardedModel(Rng& rng, uint32_t centres = 6) {
  test::RandomModelSpec spec;
  spec.noveltyCentres = centres;
  return test::makeRandomModel(rng, spec);
}

// The definition, in double: sqrt(min_c |x - c|^2 / D) / unit with x the normalised Theta.
double bruteNovelty(const Model& m, const std::vector<float>& theta) {
  const NoveltyGuard& g = m.noveltyGuard;
  double best = std::numeric_limits<double>::max();
  for (Eigen::Index c = 0; c < g.centres.rows(); ++c) {
    double d = 0;
    for (Eigen::Index i = 0; i < g.centres.cols(); ++i) {
      const double x = (double(theta[size_t(i)]) - m.inputNorm.mean[i]) / m.inputNorm.scale[i];
      d += (x - g.centres(c, i)) * (x - g.centres(c, i));
    }
    best = std::min(best, d);
  }
  return std::sqrt(best / double(g.centres.cols())) / g.unit;
}

}  // namespace

TEST(NoveltyGuard, MeasureIsTheDistanceToTheNearestCentre) {
  const uint64_t seed = test::announcedTestSeed(501);
  Rng rng(seed);
  const Model m = guardedModel(rng);
  const NoveltyGuardEvaluator g(m);
  ASSERT_TRUE(g.active());
  const uint32_t n = 9;
  const size_t D = size_t(m.thetaSize());
  std::vector<float> theta(n * D), novelty(n);
  for (float& t : theta) t = rng.uniformf(-1.f, 1.f);
  // Character 0 sits exactly on centre 2 (denormalised): novelty 0 up to the float rounding of the
  // expanded |x|^2 - 2 c.x + |c|^2 (about D * 1e-7 * |x|^2 under the square root).
  for (size_t i = 0; i < D; ++i)
    theta[i] = m.noveltyGuard.centres(2, Eigen::Index(i)) * m.inputNorm.scale[Eigen::Index(i)] +
               m.inputNorm.mean[Eigen::Index(i)];
  g.measure(theta, n, novelty);
  EXPECT_LT(novelty[0], 2e-3f);
  // Elsewhere the squared distances are O(1) per input, far above that rounding: 1e-4 relative.
  for (uint32_t c = 1; c < n; ++c) {
    const std::vector<float> one(theta.begin() + c * D, theta.begin() + (c + 1) * D);
    const double want = bruteNovelty(m, one);
    EXPECT_NEAR(novelty[c], want, 1e-4 * want + 1e-6) << "character " << c;
    EXPECT_NEAR(g.measureOne(one), novelty[c], 1e-5f * novelty[c]);  // GEMV against GEMM: sums reordered
  }
  // A non-finite input is as novel as it gets.
  theta[3] = std::numeric_limits<float>::quiet_NaN();
  g.measure(theta, n, novelty);
  EXPECT_TRUE(std::isinf(novelty[0]));
  EXPECT_THROW(g.measure(theta, n + 1, novelty), Error);
}

TEST(NoveltyGuard, ClampsThenBlendsTowardsTheMeanShape) {
  Rng rng(test::testSeed(502));
  const Model m = guardedModel(rng);
  const NoveltyGuardEvaluator g(m);
  const NoveltyGuard& ng = m.noveltyGuard;  // blend 1.5 .. 3 (random_model.cpp)
  const size_t K = size_t(m.meshComponents());
  std::vector<float> raw(K);
  for (size_t k = 0; k < K; ++k) raw[k] = k % 2 ? 5.f : -5.f;  // outside every range
  raw[0] = 0.5f * (ng.weightMin[0] + ng.weightMax[0]);         // inside its range
  auto guarded = [&](float novelty) {
    std::vector<float> w = raw;
    g.apply(novelty, w);
    return w;
  };
  const std::vector<float> near = guarded(1.f), half = guarded(2.25f), far = guarded(10.f),
                           nan = guarded(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(near[0], raw[0]);
  for (size_t k = 1; k < K; ++k) {
    EXPECT_EQ(near[k], k % 2 ? ng.weightMax[Eigen::Index(k)] : ng.weightMin[Eigen::Index(k)]) << k;
    EXPECT_FLOAT_EQ(half[k], 0.5f * near[k]) << k;
  }
  for (size_t k = 0; k < K; ++k) EXPECT_EQ(far[k], 0.f) << k;
  for (size_t k = 0; k < K; ++k) EXPECT_EQ(nan[k], 0.f) << k;
  EXPECT_EQ(g.blendOf(1.5f), 0.f);
  EXPECT_EQ(g.blendOf(3.f), 1.f);
}

TEST(NoveltyGuard, FrameEvaluatorMeasuresAppliesAndFlags) {
  Rng rng(test::testSeed(503));
  Model m = guardedModel(rng);
  const uint32_t n = 6;
  std::vector<Pose> poses;
  for (uint32_t c = 0; c < n; ++c) poses.push_back(test::makeRandomPose(rng, m.skeleton, c < 3 ? 0.1f : 2.5f));
  {  // the flag threshold between the third and fourth most novel, so that some are flagged and some not
    const NoveltyGuardEvaluator probe(m);
    std::vector<float> v;
    for (const Pose& p : poses) v.push_back(probe.measureOne(computeTheta(m.inputJoints, p.local)));
    std::sort(v.begin(), v.end());
    m.noveltyGuard.flagAbove = 0.5f * (v[2] + v[3]);
  }
  FrameEvaluator on(m, n), off(m, n, FrameEvaluatorOptions{CpuKernel::Auto, true, false});
  const FrameOutput a = on.evaluate(std::span<const Pose>(poses), 1.f / 30);
  const FrameOutput& b = off.evaluate(std::span<const Pose>(poses), 1.f / 30);
  const MlpEvaluator mlp(m, on.mlp().kernel());
  const NoveltyGuardEvaluator guard(m);
  const size_t K = size_t(m.meshComponents());
  std::vector<uint32_t> novel;
  for (uint32_t c = 0; c < n; ++c) {
    const std::vector<float> theta = computeTheta(m.inputJoints, poses[c].local);
    std::vector<float> lambda(size_t(m.lambdaSize()));
    mlp.evaluate(theta, lambda);
    // The batch's distances come from one matrix product, a single character's from a matrix-vector
    // product: the same sums in another order, equal to a few float ulps.
    EXPECT_NEAR(a.novelty[c], guard.measureOne(theta), 1e-5f * a.novelty[c]);
    const float nv = a.novelty[c];
    EXPECT_EQ(b.novelty[c], nv);  // measured with the guard off too
    if (nv > m.noveltyGuard.flagAbove) novel.push_back(c);
    EXPECT_EQ(a.guardBlend[c], guard.blendOf(nv));
    EXPECT_EQ(b.guardBlend[c], 0.f);
    std::vector<float> guarded(lambda.begin(), lambda.begin() + long(K));
    guard.apply(nv, guarded);
    for (size_t k = 0; k < K; ++k) {
      EXPECT_EQ(a.meshWeights[c * K + k], guarded[k]) << c << " " << k;
      EXPECT_EQ(b.meshWeights[c * K + k], lambda[k]) << c << " " << k;
    }
  }
  EXPECT_EQ(a.novel, novel);
  EXPECT_EQ(b.novel, novel);
  EXPECT_EQ(novel.size(), 3u);

  // A model without a guard (before format 1.2): NaN novelty, weights untouched, nothing flagged.
  Model plain = m;
  plain.noveltyGuard = {};
  FrameEvaluator none(plain, n);
  const FrameOutput& c = none.evaluate(std::span<const Pose>(poses), 1.f / 30);
  EXPECT_FALSE(none.hasNoveltyGuard());
  EXPECT_TRUE(std::all_of(c.novelty.begin(), c.novelty.end(), [](float v) { return std::isnan(v); }));
  EXPECT_TRUE(c.novel.empty());
  EXPECT_EQ(c.meshWeights, b.meshWeights);
  // The evaluator of a guard-less model measures nothing and changes nothing (the bake's evaluation and
  // the CPU prediction call it on every model).
  const NoveltyGuardEvaluator absent(plain);
  const std::vector<float> theta = computeTheta(plain.inputJoints, poses[0].local);
  EXPECT_TRUE(std::isnan(absent.measureOne(theta)));
  std::vector<float> w(K, 7.f);
  absent.apply(absent.measureOne(theta), w);
  EXPECT_EQ(w, std::vector<float>(K, 7.f));
}

// The fit: training poses' novelty has its 95th percentile at 1 (the unit's definition), the clamp is
// the training weights' range, and poses far outside the training inputs read as novel.
TEST(NoveltyGuard, FitPutsTheTrainingSetsSparseEdgeAtOne) {
  Rng rng(test::testSeed(504));
  Model m = test::makeRandomModel(rng);
  const Eigen::Index D = m.thetaSize(), n = 400, K = m.meshComponents();
  MatXf theta(D, n), weights(K, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Pose p = test::makeRandomPose(rng, m.skeleton, 0.4f);
    const std::vector<float> t = computeTheta(m.inputJoints, p.local);
    theta.col(i) = Eigen::Map<const VecXf>(t.data(), D);
    for (Eigen::Index k = 0; k < K; ++k) weights(k, i) = rng.uniformf(-2.f, 3.f);
  }
  bake::NoveltyGuardFitOptions o;
  o.centres = 32;
  m.noveltyGuard = bake::fitNoveltyGuard(m, theta, weights, o);
  m.validate("fitted");
  EXPECT_EQ(m.noveltyGuard.centres.rows(), 32);
  EXPECT_EQ(m.noveltyGuard.weightMin, weights.rowwise().minCoeff());
  EXPECT_EQ(m.noveltyGuard.weightMax, weights.rowwise().maxCoeff());
  const NoveltyGuardEvaluator g(m);
  std::vector<float> nv(static_cast<size_t>(n));
  g.measure(std::span<const float>(theta.data(), size_t(theta.size())), uint32_t(n), nv);
  const size_t below = size_t(std::count_if(nv.begin(), nv.end(), [](float v) { return v <= 1.f; }));
  EXPECT_GE(below, size_t(0.95 * double(n)));
  EXPECT_LE(below, size_t(0.95 * double(n)) + 2);
  // Poses turned 2.5 radians per joint lie well outside the 0.4-radian training set.
  size_t far = 0;
  for (int i = 0; i < 20; ++i)
    far += g.measureOne(computeTheta(m.inputJoints, test::makeRandomPose(rng, m.skeleton, 2.5f).local)) > 1.5f;
  EXPECT_GE(far, 18u);
}
