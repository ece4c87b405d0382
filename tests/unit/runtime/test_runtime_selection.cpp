// Runtime, per-frame CPU side: nearest-code search in the normal-map database, the temporal filter, and
// the CPU model of the blended map (weights over database maps).
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <vector>

#include "support/random_model.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/blended_map_weights.hpp"
#include "swish/runtime/mlp_kernel.hpp"
#include "swish/runtime/nearest_code.hpp"
#include "swish/runtime/temporal_filter.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Brute force in double, lowest index on ties: the specification of the search.
uint32_t nearestDouble(const MatXf& keys, const float* code, double* best = nullptr) {
  uint32_t idx = 0;
  double bestD = std::numeric_limits<double>::infinity();
  for (Eigen::Index m = 0; m < keys.rows(); ++m) {
    double s = 0;
    for (Eigen::Index d = 0; d < keys.cols(); ++d) s += std::pow(double(code[d]) - keys(m, d), 2);
    if (s < bestD) {
      bestD = s;
      idx = uint32_t(m);
    }
  }
  if (best) *best = bestD;
  return idx;
}

}  // namespace

// ---- Nearest code ----

TEST(RuntimeNearestCode, MatchesBruteForceOnRandomDatabases) {
  const uint64_t seed = test::testSeed(301);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  // Sizes around the 8-lane blocks and the 64-key register groups of the AVX2 kernel.
  for (int maps : {1, 7, 8, 9, 63, 64, 65, 128, 131, 1500}) {
    for (int dims : {1, 3, 8, 17, 32}) {
      MatXf keys(maps, dims);
      for (Eigen::Index i = 0; i < keys.size(); ++i) keys.data()[i] = float(rng.normal());
      for (CpuKernel k : availableCpuKernels()) {
        const NearestCodeSearch search(keys, k);
        for (int q = 0; q < 20; ++q) {
          std::vector<float> code(dims);
          for (float& c : code) c = float(rng.normal(0, 1.2));
          double bestD = 0;
          const uint32_t expect = nearestDouble(keys, code.data(), &bestD);
          const NearestCode r = search.find(code);
          ASSERT_TRUE(r.found);
          // The float search may pick another key only if its true distance is within float rounding of
          // the best one (dims + 1 roundings of values <= the distance).
          if (r.index != expect) {
            double d = 0;
            for (int j = 0; j < dims; ++j) d += std::pow(double(code[j]) - keys(r.index, j), 2);
            EXPECT_LE(d - bestD, (dims + 2) * std::ldexp(1.0, -23) * d) << maps << "x" << dims;
          }
          EXPECT_NEAR(r.distanceSquared, bestD, 1e-5 * (1 + bestD));
        }
      }
    }
  }
}

TEST(RuntimeNearestCode, TiesGoToTheLowestIndex) {
  // Keys 1 and 3 are duplicates, keys 0 and 2 are at the same distance from the origin as each other.
  MatXf keys(5, 2);
  keys << 3, 0, 1, 1, 0, 3, 1, 1, -1, -1;
  for (CpuKernel k : availableCpuKernels()) {
    const NearestCodeSearch search(keys, k);
    const float atDuplicate[2] = {1, 1};
    EXPECT_EQ(search.find(atDuplicate).index, 1u) << toString(k);
    const float between[2] = {0, 0};  // keys 1, 3 and 4 all at squared distance 2
    EXPECT_EQ(search.find(between).index, 1u);
    const float nearFar[2] = {1.5f, 1.5f};  // keys 0 and 2 at 4.5, keys 1 and 3 at 0.5
    EXPECT_EQ(search.find(nearFar).index, 1u);
    const float equidistant02[2] = {10, 10};  // keys 0 and 2 tie at 149, keys 1 and 3 at 162: the lower, 0
    EXPECT_EQ(search.find(equidistant02).index, 0u);
    const float onAxis[2] = {3, 3};  // keys 0 and 2 at 9, keys 1 and 3 at 8: still 1
    EXPECT_EQ(search.find(onAxis).index, 1u);
  }
  // 100 identical keys: always 0; with the first removed from equality, the second.
  MatXf same = MatXf::Constant(100, 4, 0.5f);
  same(0, 0) = 9.f;
  for (CpuKernel k : availableCpuKernels()) {
    const float code[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    EXPECT_EQ(NearestCodeSearch(same, k).find(code).index, 1u);
  }
}

TEST(RuntimeNearestCode, NonFiniteCodeReturnsTheFallbackNotFound) {
  MatXf keys(4, 3);
  keys.setRandom();
  for (CpuKernel k : availableCpuKernels()) {
    const NearestCodeSearch search(keys, k);
    for (float bad : {kNaN, kInf, -kInf}) {
      const float code[3] = {0.f, bad, 0.f};
      const NearestCode r = search.find(code, 2);
      EXPECT_FALSE(r.found);
      EXPECT_EQ(r.index, 2u);
      EXPECT_TRUE(std::isnan(r.distanceSquared));
    }
    EXPECT_FALSE(search.find(std::vector<float>{kNaN, 0, 0}).found);
    EXPECT_EQ(search.find(std::vector<float>{kNaN, 0, 0}).index, 0u);  // default fallback
  }
}

TEST(RuntimeNearestCode, HugeFiniteCodeStillFindsItsTrueNearestKey) {
  // Float distances overflow for every key; the double-precision rescue finds the right one.
  // Every key is over 1.9e19 from the code: squared distances above FLT_MAX (3.4e38).
  MatXf keys(3, 2);
  keys << 0, 0, 3e19f, 0, 5e19f, 0;
  for (CpuKernel k : availableCpuKernels()) {
    const NearestCodeSearch search(keys, k);
    const float code[2] = {1e20f, 0.f};
    const NearestCode r = search.find(code);
    EXPECT_TRUE(r.found);
    EXPECT_EQ(r.index, 2u);
    EXPECT_EQ(r.distanceSquared, kInf);  // the distance itself does not fit a float
    const float negative[2] = {-1e20f, -1e20f};
    EXPECT_EQ(search.find(negative).index, 0u);
  }
}

TEST(RuntimeNearestCode, RejectsBadDatabasesAndCodeSizes) {
  EXPECT_THROW(NearestCodeSearch(MatXf(0, 3)), Error);
  EXPECT_THROW(NearestCodeSearch(MatXf(3, 0)), Error);
  MatXf bad = MatXf::Zero(3, 2);
  bad(1, 1) = kNaN;
  EXPECT_THROW(NearestCodeSearch{bad}, Error);
  const NearestCodeSearch ok(MatXf::Zero(3, 2));
  EXPECT_THROW(ok.find(std::vector<float>{1, 2, 3}), Error);
}

// ---- Temporal filter ----

TEST(RuntimeTemporalFilter, AlphaFollowsTheExponentialAndItsEdgeCases) {
  const float tc = 0.1f;
  EXPECT_NEAR(TemporalFilter::alphaFor(1.f / 60, tc), 1 - std::exp(-1.0 / 6.0), 1e-7);
  EXPECT_NEAR(TemporalFilter::alphaFor(0.1f, tc), 1 - std::exp(-1.0), 1e-7);
  EXPECT_EQ(TemporalFilter::alphaFor(0.f, tc), 0.f);   // dt = 0: nothing changes
  EXPECT_EQ(TemporalFilter::alphaFor(1e6f, tc), 1.f);  // huge dt: the selection shows
  EXPECT_EQ(TemporalFilter::alphaFor(kInf, tc), 1.f);
  EXPECT_EQ(TemporalFilter::alphaFor(1.f / 60, 0.f), 1.f);   // time constant 0: no filtering
  EXPECT_EQ(TemporalFilter::alphaFor(1e-30f, 1e-38f), 1.f);  // dt / tc overflows float: still 1
  // Tiny dt: alpha ~ dt / tc with full relative precision (expm1, not 1 - exp).
  EXPECT_NEAR(TemporalFilter::alphaFor(1e-9f, 1.f), 1e-9, 1e-16);
  bool invalid = false;
  EXPECT_EQ(TemporalFilter::alphaFor(-0.01f, tc, &invalid), 0.f);
  EXPECT_TRUE(invalid);
  EXPECT_EQ(TemporalFilter::alphaFor(kNaN, tc, &invalid), 0.f);
  EXPECT_TRUE(invalid);
  EXPECT_EQ(TemporalFilter::alphaFor(-kInf, tc, &invalid), 0.f);
  EXPECT_TRUE(invalid);
  TemporalFilter::alphaFor(0.f, tc, &invalid);
  EXPECT_FALSE(invalid);
  // Frame-rate independence: two half steps blend as much as one whole step.
  const double half = TemporalFilter::alphaFor(0.02f, tc), whole = TemporalFilter::alphaFor(0.04f, tc);
  EXPECT_NEAR(1 - (1 - half) * (1 - half), whole, 1e-7);
}

TEST(RuntimeTemporalFilter, FirstFrameAndResetHaveNoHistory) {
  TemporalFilter f(0.2f);
  EXPECT_FALSE(f.hasHistory());
  BlendStep s = f.step(0.f, 5);  // even with dt = 0 the first frame shows its selection
  EXPECT_TRUE(s.firstFrame);
  EXPECT_EQ(s.alpha, 1.f);
  EXPECT_EQ(s.selectedMap, 5u);
  s = f.step(0.f, 6);
  EXPECT_FALSE(s.firstFrame);
  EXPECT_EQ(s.alpha, 0.f);
  s = f.step(kNaN, 6);
  EXPECT_TRUE(s.invalidDt);
  EXPECT_EQ(s.alpha, 0.f);
  f.reset();
  s = f.step(kNaN, 7);  // no history: alpha 1 whatever dt is, still reported
  EXPECT_TRUE(s.firstFrame);
  EXPECT_TRUE(s.invalidDt);
  EXPECT_EQ(s.alpha, 1.f);
  EXPECT_THROW(TemporalFilter{-1.f}, Error);
  EXPECT_THROW(TemporalFilter{kNaN}, Error);
  EXPECT_THROW(TemporalFilter{kInf}, Error);
}

TEST(RuntimeBlendedMapWeights, ModelsTheExponentialBlendExactly) {
  TemporalFilter f(0.1f);
  BlendedMapWeights w(4);
  EXPECT_EQ(w.total(), 0.0);
  const float dt = 1.f / 30;
  w.apply(f.step(dt, 2));
  EXPECT_EQ(w.weight(2), 1.0);
  const double a = TemporalFilter::alphaFor(dt, 0.1f);
  w.apply(f.step(dt, 0));
  w.apply(f.step(dt, 0));
  // Map 2 decays by (1 - a) twice; map 0 got a, then a + (1 - a) a.
  EXPECT_NEAR(w.weight(2), (1 - a) * (1 - a), 1e-12);
  EXPECT_NEAR(w.weight(0), a + (1 - a) * a, 1e-12);
  EXPECT_EQ(w.weight(1), 0.0);
  EXPECT_NEAR(w.total(), 1.0, 1e-12);
  // A mixed blend applied texel-wise (what the GPU does) equals the weighted sum of the maps.
  const double maps[4] = {0.9, -0.3, 0.25, 0.5};  // one texel channel of each map
  TemporalFilter g(0.1f);
  BlendedMapWeights wg(4);
  double texel = 0;
  Rng rng(test::testSeed(302));
  for (int frame = 0; frame < 50; ++frame) {
    const BlendStep s = g.step(rng.uniformf(0.f, 0.1f), uint32_t(rng.below(4)));
    const double a = s.alpha;
    texel = texel * (1 - a) + maps[s.selectedMap] * a;  // mix(out, decoded, alpha), in double
    wg.apply(s);
  }
  double modelled = 0;
  for (uint32_t m = 0; m < 4; ++m) modelled += wg.weight(m) * maps[m];
  EXPECT_NEAR(modelled, texel, 1e-12);
  BlendStep outside;
  outside.selectedMap = 4;
  EXPECT_THROW(wg.apply(outside), Error);
}
