// Bake PCA: exact and randomised fits recover a known low-rank model; explained variance and
// truncation error per K are consistent; zero-variance data stays finite.
#include <gtest/gtest.h>

#include "support/random_model.hpp"
#include "swish/bake/compression/pca.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
// D x N samples = mean + basis(D x r) * diag(sigma) * codes + noise.
MatXf lowRankSamples(Rng& rng, int d, int n, int r, float noise) {
  MatXf basis(d, r), codes(r, n);
  for (int j = 0; j < r; ++j)
    for (int i = 0; i < d; ++i) basis(i, j) = float(rng.normal());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < r; ++i) codes(i, j) = float(rng.normal() * (10.0 / (i + 1)));
  MatXf x = basis * codes;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < d; ++i) x(i, j) += 3.f + noise * float(rng.normal());
  return x;
}
}  // namespace

TEST(BakePca, ExactFitRecoversLowRankDataAndReportsPerKErrors) {
  const uint64_t seed = test::testSeed(101);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  const MatXf x = lowRankSamples(rng, 60, 40, 5, 0.f);
  PcaOptions o;
  o.method = PcaOptions::Method::Exact;
  const PcaResult p = fitPca(x, o);
  EXPECT_EQ(p.components(), 5);  // rank-limited
  EXPECT_NEAR(p.explainedVariance[5], 1.0, 1e-6);
  EXPECT_LT(p.explainedVariance[1], p.explainedVariance[2]);
  for (int k = 1; k < p.residualSquaredNorm.size(); ++k)
    EXPECT_LE(p.residualSquaredNorm[k], p.residualSquaredNorm[k - 1] + 1e-6);
  const MatXf back = p.reconstruct(p.project(x));
  EXPECT_LT((back - x).cwiseAbs().maxCoeff(), 1e-3f);
  EXPECT_LT((p.basis.transpose() * p.basis - MatXf::Identity(5, 5)).cwiseAbs().maxCoeff(), 1e-5f);
}

TEST(BakePca, ResidualPerKMatchesTheActualReconstructionError) {
  Rng rng(test::testSeed(102));
  const MatXf x = lowRankSamples(rng, 50, 30, 8, 0.1f);
  PcaOptions o;
  o.maxComponents = 3;
  const PcaResult p = fitPca(x, o);
  ASSERT_EQ(p.components(), 3);
  const double actual = (p.reconstruct(p.project(x)) - x).cast<double>().squaredNorm();
  EXPECT_NEAR(actual, p.residualSquaredNorm[3], 1e-3 * p.totalSquaredNorm);
}

TEST(BakePca, RandomizedAgreesWithExactOnTheLeadingSubspace) {
  Rng rng(test::testSeed(103));
  const MatXf x = lowRankSamples(rng, 400, 60, 6, 0.01f);
  PcaOptions e, r;
  e.maxComponents = r.maxComponents = 6;
  e.method = PcaOptions::Method::Exact;
  r.method = PcaOptions::Method::Randomized;
  const PcaResult pe = fitPca(x, e), pr = fitPca(x, r);
  EXPECT_TRUE(pr.randomized);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(pr.singularValues[k], pe.singularValues[k], 1e-3 * pe.singularValues[0]);
  // Same subspace: projector difference is small.
  const MatXf projE = pe.basis * pe.basis.transpose(), projR = pr.basis * pr.basis.transpose();
  EXPECT_LT((projE - projR).norm(), 1e-2f);
}

TEST(BakePca, VarianceTargetPicksTheSmallestSufficientK) {
  Rng rng(test::testSeed(104));
  const MatXf x = lowRankSamples(rng, 80, 50, 10, 0.f);
  PcaOptions o;
  o.varianceToKeep = 0.9;
  const PcaResult p = fitPca(x, o);
  const int k = p.components();
  EXPECT_GE(p.explainedVariance[k], 0.9);
  EXPECT_LT(p.explainedVariance[k - 1], 0.9);
}

TEST(BakePca, ZeroVarianceDataGivesFiniteOutputAndOneComponent) {
  MatXf x = MatXf::Constant(30, 12, 0.25f);
  for (auto m : {PcaOptions::Method::Exact, PcaOptions::Method::Randomized}) {
    PcaOptions o;
    o.method = m;
    o.maxComponents = 4;
    const PcaResult p = fitPca(x, o);
    EXPECT_EQ(p.components(), 1);
    EXPECT_TRUE(p.basis.allFinite());
    EXPECT_TRUE(p.explainedVariance.allFinite());
    EXPECT_DOUBLE_EQ(p.explainedVariance[0], 1.0);
    EXPECT_TRUE(p.project(x).allFinite());
    EXPECT_LT((p.reconstruct(p.project(x)) - x).cwiseAbs().maxCoeff(), 1e-6f);
  }
}

TEST(BakePca, BadInputIsAnError) {
  EXPECT_THROW(fitPca(MatXf(0, 0), {}), Error);
  MatXf x = MatXf::Ones(4, 4);
  x(1, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(fitPca(x, {}), Error);
  PcaOptions o;
  o.varianceToKeep = 1.5;
  EXPECT_THROW(fitPca(MatXf::Ones(4, 4), o), Error);
}
