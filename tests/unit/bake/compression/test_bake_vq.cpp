// VQ of normal maps: layout round trip, exactness on maps the codebook can hold, error against the
// BC5 baseline on smooth sinusoidal maps, memory accounting, and the angular error metric.
#include <gtest/gtest.h>

#include <cmath>

#include "support/random_model.hpp"
#include "swish/bake/compression/bc5_baseline.hpp"
#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/compression/normal_map_pca.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
// Smooth wrinkle-like detail: a few sinusoids with random direction, frequency and phase.
NormalMapImage sinusoidMap(Rng& rng, uint32_t size, int waves = 3) {
  NormalMapImage m{size, size, std::vector<float>(size_t(size) * size * 2, 0.f)};
  for (int w = 0; w < waves; ++w) {
    const double angle = rng.uniform(0, M_PI), freq = rng.uniform(1, 6), phase = rng.uniform(0, 2 * M_PI);
    const double amp = rng.uniform(0.05, 0.2);
    for (uint32_t y = 0; y < size; ++y)
      for (uint32_t x = 0; x < size; ++x) {
        const double u = (x + .5) / size, v = (y + .5) / size;
        const double s = std::cos(2 * M_PI * freq * (u * std::cos(angle) + v * std::sin(angle)) + phase);
        m.xy[2 * (size_t(y) * size + x)] += float(amp * s * std::cos(angle));
        m.xy[2 * (size_t(y) * size + x) + 1] += float(amp * s * std::sin(angle));
      }
  }
  return m;
}
}  // namespace

TEST(BakeAngularError, KnownAngles) {
  EXPECT_NEAR(texelAngleDegrees(0, 0, 0, 0), 0.0, 1e-9);
  const float s = float(std::sin(M_PI / 6));  // 30 degrees tilt about y
  EXPECT_NEAR(texelAngleDegrees(0, 0, s, 0), 30.0, 1e-4);
  EXPECT_NEAR(texelAngleDegrees(-s, 0, s, 0), 60.0, 1e-4);
  AngularErrorAccumulator acc;
  for (int i = 1; i <= 100; ++i) acc.add(double(i));
  const auto st = acc.stats();
  EXPECT_NEAR(st.meanDegrees, 50.5, 1e-9);
  EXPECT_NEAR(st.p95Degrees, 95.0, 0.011);
  EXPECT_DOUBLE_EQ(st.maxDegrees, 100.0);
}

TEST(BakeVq, ExactWhenTheCodebookHoldsEveryBlock) {
  // Maps built from 5 distinct snorm8-exact blocks: the VQ must reproduce them bit for bit.
  Rng rng(test::testSeed(301));
  std::vector<std::vector<float>> palette(5, std::vector<float>(32));
  for (auto& b : palette)
    for (float& v : b) v = float(int(rng.below(101)) - 50) / 127.f;
  std::vector<NormalMapImage> maps(3, NormalMapImage{16, 8, std::vector<float>(16 * 8 * 2)});
  for (auto& m : maps)
    for (uint32_t by = 0; by < 2; ++by)
      for (uint32_t bx = 0; bx < 4; ++bx) {
        const auto& b = palette[rng.below(5)];
        for (uint32_t t = 0; t < 16; ++t)
          for (int c = 0; c < 2; ++c) m.xy[2 * ((by * 4 + t / 4) * 16 + bx * 4 + t % 4) + c] = b[2 * t + c];
      }
  std::vector<const NormalMapImage*> ptrs{&maps[0], &maps[1], &maps[2]};
  VqOptions o;
  o.codebookSize = 16;
  NormalMapDatabase db;
  db.keys = MatXf::Zero(3, 1);
  const VqReport rep = encodeVq(ptrs, o, db);
  EXPECT_LE(rep.codebookEntries, 5u);
  EXPECT_EQ(rep.indexBytes, 3u * 8 * 2);
  for (uint32_t m = 0; m < 3; ++m) {
    const NormalMapImage d = decodeVqMap(db, m);
    for (size_t i = 0; i < d.xy.size(); ++i) ASSERT_FLOAT_EQ(d.xy[i], maps[m].xy[i]) << "map " << m << " value " << i;
  }
}

TEST(BakeVq, BeatsBc5MemoryAtComparableErrorOnSmoothMaps) {
  const uint64_t seed = test::testSeed(302);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  std::vector<NormalMapImage> maps;
  for (int i = 0; i < 8; ++i) maps.push_back(sinusoidMap(rng, 64));
  std::vector<const NormalMapImage*> ptrs;
  for (auto& m : maps) ptrs.push_back(&m);
  VqOptions o;
  o.codebookSize = 256;
  o.seed = 5;
  NormalMapDatabase db;
  db.keys = MatXf::Zero(8, 1);
  const VqReport rep = encodeVq(ptrs, o, db);
  AngularErrorAccumulator vq, bc5;
  for (uint32_t m = 0; m < 8; ++m) {
    vq.addMaps(maps[m], decodeVqMap(db, m));
    bc5.addMaps(maps[m], bc5RoundTrip(maps[m]));
  }
  const double vqMean = vq.stats().meanDegrees, bc5Mean = bc5.stats().meanDegrees;
  EXPECT_GT(bc5Mean, 0.0);
  EXPECT_LT(bc5Mean, 1.0);  // BC5 of smooth maps is good (8-bit endpoints, 8 levels per block)
  EXPECT_LT(vqMean, 2.0);   // smooth maps, 256 entries: well under the 1.5-degree budget's scale
  EXPECT_LT(rep.totalBytes(), 8 * bc5Bytes(64, 64));
  // Deterministic for a seed.
  NormalMapDatabase again;
  again.keys = db.keys;
  encodeVq(ptrs, o, again);
  EXPECT_EQ(again.indices, db.indices);
  EXPECT_EQ(again.codebook, db.codebook);
}

TEST(BakeVq, RejectsBadSizesAndOptions) {
  NormalMapImage odd{6, 6, std::vector<float>(72, 0.f)};
  NormalMapDatabase db;
  EXPECT_THROW(encodeVq({&odd}, {}, db), Error);
  NormalMapImage ok{8, 8, std::vector<float>(128, 0.f)};
  VqOptions o;
  o.codebookSize = 70000;
  EXPECT_THROW(encodeVq({&ok}, o, db), Error);
  NormalMapImage other{4, 4, std::vector<float>(32, 0.f)};
  EXPECT_THROW(encodeVq({&ok, &other}, {}, db), Error);
}

TEST(BakeVq, ConstantMapsGiveOneEntryAndNoError) {
  NormalMapImage flat{8, 8, std::vector<float>(128, 0.f)};
  NormalMapDatabase db;
  db.keys = MatXf::Zero(2, 1);
  const VqReport rep = encodeVq({&flat, &flat}, {}, db);
  EXPECT_EQ(rep.codebookEntries, 1u);
  EXPECT_DOUBLE_EQ(angularError(flat, decodeVqMap(db, 1)).maxDegrees, 0.0);
}

TEST(BakeNormalMapPca, CodesSeparateDifferentPatterns) {
  Rng rng(test::testSeed(303));
  std::vector<NormalMapImage> maps;
  for (int i = 0; i < 12; ++i) maps.push_back(sinusoidMap(rng, 16, 1));
  std::vector<const NormalMapImage*> ptrs;
  for (auto& m : maps) ptrs.push_back(&m);
  const NormalMapPca p = fitNormalMapPca(ptrs, 4, 9);
  EXPECT_EQ(p.codeDims(), 4);
  EXPECT_EQ(p.codes.cols(), 12);
  EXPECT_LT((normalMapCode(p.pca, maps[3]) - p.codes.col(3)).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_GT((p.codes.col(0) - p.codes.col(1)).norm(), 1e-3f);
}

TEST(BakeBc5AtEqualMemory, SizeFitsTheBytesAndKeepsBlocksWhole) {
  EXPECT_EQ(bc5SizeWithin(256, 256, bc5Bytes(256, 256)), std::make_pair(256u, 256u));  // all it needs: full size
  const auto [w, h] = bc5SizeWithin(256, 256, 12288);  // the default model's VQ bytes per map
  EXPECT_EQ(w % 4, 0u);
  EXPECT_EQ(h % 4, 0u);
  EXPECT_LE(bc5Bytes(w, h), 12288u);
  EXPECT_GT(bc5Bytes(w + 4, h + 4), 12288u);  // the largest that fits
  EXPECT_EQ(w, 108u);                         // 27 x 27 blocks of 16 bytes = 11664 bytes
  EXPECT_EQ(bc5SizeWithin(256, 128, 16 * 8 * 4).second * 2, bc5SizeWithin(256, 128, 16 * 8 * 4).first);  // aspect
  EXPECT_EQ(bc5SizeWithin(64, 64, 15), std::make_pair(0u, 0u));  // not one block
}

TEST(BakeBc5AtEqualMemory, LowFrequencySurvivesHighFrequencyDoesNot) {
  // A map that varies slowly loses little at half resolution; one that alternates every texel
  // averages to flat (box filter), so its error is the whole detail's angle.
  NormalMapImage slow{64, 64, std::vector<float>(64 * 64 * 2)}, fast = slow;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      slow.xy[2 * (y * 64 + x)] = 0.3f * float(std::sin(2 * M_PI * (x + 0.5) / 64.0));
      fast.xy[2 * (y * 64 + x)] = (x % 2 ? 0.3f : -0.3f);
    }
  AngularErrorAccumulator a, b, full;
  a.addMaps(slow, bc5RoundTripResized(slow, 32, 32));
  b.addMaps(fast, bc5RoundTripResized(fast, 32, 32));
  full.addMaps(slow, bc5RoundTrip(slow));
  EXPECT_LT(a.stats().meanDegrees, 1.5);
  const double detail = std::asin(0.3) * 180.0 / M_PI;  // 17.5 degrees off the flat normal
  EXPECT_NEAR(b.stats().meanDegrees, detail, 1.0);
  EXPECT_LE(full.stats().meanDegrees, a.stats().meanDegrees);  // the full size is no worse
  EXPECT_THROW(bc5RoundTripResized(slow, 128, 32), Error);     // no upsizing
  EXPECT_THROW(bc5RoundTripResized(slow, 0, 32), Error);
}
