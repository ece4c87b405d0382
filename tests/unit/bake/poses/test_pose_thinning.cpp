// Greedy pose thinning: the two guarantees, equality with a plain brute-force greedy pass, determinism,
// and bisection to a target count.
#include <gtest/gtest.h>

#include <cmath>

#include "support/random_model.hpp"
#include "swish/bake/poses/pose_thinning.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

// Several random walks (like recordings: consecutive samples close), in `dim` dimensions.
PoseSamples randomWalks(size_t walks, size_t steps, int dim, uint64_t seed) {
  Rng rng(seed);
  PoseSamples s;
  s.dim = dim;
  for (size_t w = 0; w < walks; ++w) {
    std::vector<float> x(static_cast<size_t>(dim));
    for (auto& v : x) v = float(rng.normal());
    for (size_t t = 0; t < steps; ++t) {
      for (auto& v : x) v += float(0.05 * rng.normal());
      s.values.insert(s.values.end(), x.begin(), x.end());
      s.origins.push_back({uint32_t(w), 0, float(t), false});
    }
  }
  return s;
}

float distance(const PoseSamples& s, size_t a, size_t b) {
  double d = 0;
  for (int k = 0; k < s.dim; ++k) d += std::pow(double(s.row(a)[k]) - s.row(b)[k], 2);
  return float(std::sqrt(d));
}

// The definition, without acceleration: the reference the fast pass must equal.
std::vector<uint32_t> bruteForceGreedy(const PoseSamples& s, float tol, const std::vector<uint32_t>& first = {}) {
  std::vector<uint32_t> kept = first;
  for (size_t i = 0; i < s.size(); ++i) {
    bool covered = false;
    for (uint32_t k : kept) {
      double d = 0;
      for (int c = 0; c < s.dim; ++c) d += double(s.row(i)[c] - s.row(k)[c]) * double(s.row(i)[c] - s.row(k)[c]);
      // Same float arithmetic as the library's early-exit check would be ideal; a sample at exactly
      // the tolerance is vanishingly unlikely with random data.
      if (d <= double(tol) * tol) {
        covered = true;
        break;
      }
    }
    if (!covered) kept.push_back(uint32_t(i));
  }
  return kept;
}

}  // namespace

TEST(PoseThinning, KeptPosesAreSeparatedAndEveryRejectedPoseIsCovered) {
  const PoseSamples s = randomWalks(8, 1500, 30, test::testSeed(3));
  const float tol = 1.5f;
  const ThinningResult r = thinPoses(s, tol);
  ASSERT_GT(r.kept.size(), 20u);
  ASSERT_LT(r.kept.size(), s.size() / 10);
  for (size_t a = 0; a < r.kept.size(); ++a)
    for (size_t b = a + 1; b < r.kept.size(); ++b) ASSERT_GT(distance(s, r.kept[a], r.kept[b]), tol);
  std::vector<bool> isKept(s.size(), false);
  for (uint32_t k : r.kept) isKept[k] = true;
  for (size_t i = 0; i < s.size(); ++i) {
    if (isKept[i]) continue;
    float best = INFINITY;
    for (uint32_t k : r.kept) best = std::min(best, distance(s, i, k));
    ASSERT_LE(best, tol * (1 + 1e-5f)) << "sample " << i << " was rejected but no kept pose covers it";
  }
}

TEST(PoseThinning, EqualsBruteForceGreedy) {
  for (uint64_t seed : {4u, 5u}) {
    const PoseSamples s = randomWalks(5, 800, 12, test::testSeed(seed));
    for (float tol : {0.5f, 0.9f, 2.f})
      EXPECT_EQ(thinPoses(s, tol).kept, bruteForceGreedy(s, tol)) << "tolerance " << tol;
  }
}

TEST(PoseThinning, DeterministicAndTruncatesAtMaxKept) {
  const PoseSamples s = randomWalks(6, 1000, 30, test::testSeed(5));
  const ThinningResult a = thinPoses(s, 1.0f), b = thinPoses(s, 1.0f);
  EXPECT_EQ(a.kept, b.kept);
  EXPECT_EQ(a.distanceChecks, b.distanceChecks);
  const ThinningResult cut = thinPoses(s, 1.0f, 10);
  EXPECT_TRUE(cut.truncated);
  EXPECT_EQ(cut.kept.size(), 10u);
  EXPECT_EQ(std::vector<uint32_t>(a.kept.begin(), a.kept.begin() + 10), cut.kept);
}

TEST(PoseThinning, BisectionReachesTargetCount) {
  const PoseSamples s = randomWalks(10, 2000, 30, test::testSeed(6));
  for (size_t target : {size_t(50), size_t(300)}) {
    const ThinningResult r = thinPosesToCount(s, target);
    EXPECT_FALSE(r.truncated);
    EXPECT_LT(r.passes, 30);
    EXPECT_NEAR(double(r.kept.size()), double(target), 0.03 * double(target)) << "tolerance " << r.tolerance;
    EXPECT_EQ(thinPoses(s, r.tolerance).kept, r.kept);  // the reported tolerance reproduces the set
  }
  EXPECT_EQ(thinPosesToCount(s, s.size() + 5).kept.size(), s.size());
}

// Growing a smaller thinning (part1.thinning.grow_from): its poses stay first, in their order (so a bake
// keeps their ids and simulations), the pass equals the plain greedy pass started from them, and the
// grown set has both guarantees at its own, smaller tolerance.
TEST(PoseThinning, GrowingKeepsTheFirstPosesAndCoversAtTheSmallerTolerance) {
  const PoseSamples s = randomWalks(8, 1500, 30, test::testSeed(12));
  const ThinningResult small = thinPosesToCount(s, 100);
  ThinToCountOptions grow;
  grow.keepFirst = small.kept;
  const ThinningResult big = thinPosesToCount(s, 300, grow);
  EXPECT_FALSE(big.truncated);
  EXPECT_NEAR(double(big.kept.size()), 300.0, 0.03 * 300.0);
  ASSERT_GT(big.kept.size(), small.kept.size());
  EXPECT_EQ(std::vector<uint32_t>(big.kept.begin(), big.kept.begin() + long(small.kept.size())), small.kept);
  EXPECT_LT(big.tolerance, small.tolerance);
  EXPECT_EQ(thinPoses(s, big.tolerance, SIZE_MAX, small.kept).kept, bruteForceGreedy(s, big.tolerance, small.kept));
  // Each added pose is farther than the tolerance from every pose kept before it, first ones included.
  for (size_t a = small.kept.size(); a < big.kept.size(); ++a)
    for (size_t b = 0; b < a; ++b) EXPECT_GT(distance(s, big.kept[a], big.kept[b]), big.tolerance) << a << " " << b;
  // Every sample is within the tolerance of a kept pose.
  for (size_t i = 0; i < s.size(); i += 5) {
    float nearest = INFINITY;
    for (uint32_t k : big.kept) nearest = std::min(nearest, distance(s, i, k));
    EXPECT_LE(nearest, big.tolerance * (1.f + 1e-5f)) << "sample " << i;
  }
  // Growing to no more than is already kept, or from a list that is not a set of samples, is an error.
  EXPECT_THROW(thinPosesToCount(s, 100, grow), Error);
  ThinToCountOptions bad;
  bad.keepFirst = {3, 3};
  EXPECT_THROW(thinPosesToCount(s, 300, bad), Error);
  bad.keepFirst = {uint32_t(s.size())};
  EXPECT_THROW(thinPosesToCount(s, 300, bad), Error);
  EXPECT_THROW(thinPoses(s, 1.f, SIZE_MAX, bad.keepFirst), Error);
}

TEST(PoseThinning, NearestKeptDistanceIsTheBruteForceMinimum) {
  const PoseSamples s = randomWalks(4, 50, 6, test::testSeed(11));
  const ThinningResult t = thinPoses(s, 0.4f);
  ASSERT_GT(t.kept.size(), 3u);
  // Every sample is within the tolerance of a kept pose (the thinning's guarantee), and a kept pose
  // is at distance 0 from itself.
  for (size_t i = 0; i < s.size(); i += 7) {
    const float d = nearestKeptDistance(s, t.kept, std::span<const float>(s.row(i), size_t(s.dim)));
    float brute = INFINITY;
    for (uint32_t k : t.kept) brute = std::min(brute, distance(s, i, k));
    EXPECT_NEAR(d, brute, 1e-5f);
    EXPECT_LE(d, 0.4f + 1e-5f);
  }
  EXPECT_EQ(nearestKeptDistance(s, t.kept, std::span<const float>(s.row(t.kept[2]), size_t(s.dim))), 0.f);
  const std::vector<float> far(6, 100.f);
  EXPECT_GT(nearestKeptDistance(s, t.kept, far), 100.f);
  EXPECT_TRUE(std::isinf(nearestKeptDistance(s, {}, far)));
  EXPECT_THROW(nearestKeptDistance(s, t.kept, std::vector<float>(5, 0.f)), Error);
}

TEST(PoseThinning, BadInputIsAnError) {
  PoseSamples s = randomWalks(1, 10, 6, 1);
  EXPECT_THROW(thinPoses(s, -1.f), Error);
  EXPECT_THROW(thinPoses(s, NAN), Error);
  EXPECT_THROW(thinPosesToCount(s, 0), Error);
  s.values[7] = NAN;
  EXPECT_THROW(thinPoses(s, 1.f), Error);
  PoseSamples empty;
  empty.dim = 6;
  EXPECT_THROW(thinPosesToCount(empty, 3), Error);
}
