// PNG: 8/16-bit round trips for every channel count, the normal-map encoding, errors naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/io/png.hpp"

using namespace swish;

namespace {

io::PngImage randomImage(Rng& rng, uint32_t w, uint32_t h, uint32_t channels, uint32_t depth) {
  io::PngImage im;
  im.width = w, im.height = h, im.channels = channels, im.bitDepth = depth;
  im.samples.resize(size_t(w) * h * channels);
  // Half smooth gradient (exercises the filters), half noise (exercises stored/literal paths).
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      for (uint32_t c = 0; c < channels; ++c)
        im.at(x, y, c) = (y < h / 2) ? uint16_t((x * 37 + y * 11 + c * 1000) % (im.maxValue() + 1u))
                                     : uint16_t(rng.below(im.maxValue() + 1u));
  return im;
}

}  // namespace

TEST(Png, RoundTripsEveryChannelCountAtBothDepths) {
  Rng rng(test::testSeed(301));
  const test::TempDir tmp("test_png_roundtrip");
  const auto dir = tmp.path();
  for (uint32_t depth : {8u, 16u}) {
    for (uint32_t ch = 1; ch <= 4; ++ch) {
      const io::PngImage im = randomImage(rng, 37, 23, ch, depth);
      const auto path = dir / ("im_" + std::to_string(depth) + "_" + std::to_string(ch) + ".png");
      io::writePng(path, im);
      const io::PngImage back = io::readPng(path);
      EXPECT_EQ(back.width, im.width);
      EXPECT_EQ(back.height, im.height);
      EXPECT_EQ(back.channels, ch);
      EXPECT_EQ(back.bitDepth, depth);
      EXPECT_EQ(back.samples, im.samples) << path;
    }
  }
  // No temporary files left behind by the atomic write.
  for (const auto& e : std::filesystem::directory_iterator(dir)) EXPECT_EQ(e.path().extension(), ".png");
}

TEST(Png, NormalMapEncodingRoundTripsWithinQuantisation) {
  Rng rng(test::testSeed(302));
  const uint32_t w = 16, h = 9;
  std::vector<float> xy(w * h * 2);
  for (size_t t = 0; t < w * h; ++t) {
    const float a = float(rng.uniform(0.0, 2.0 * M_PI)), r = float(rng.uniform(0.0, 0.99));
    xy[2 * t] = r * std::cos(a);
    xy[2 * t + 1] = r * std::sin(a);
  }
  for (uint32_t depth : {8u, 16u}) {
    const io::PngImage im = io::encodeNormalMap(w, h, xy, depth);
    ASSERT_EQ(im.channels, 3u);
    const io::PngImage back = io::decodePng(io::encodePng(im), "memory");
    const std::vector<float> got = io::decodeNormalMap(back, "memory");
    const float tol = 1.f / float(im.maxValue()) + 1e-6f;
    for (size_t i = 0; i < xy.size(); ++i) EXPECT_NEAR(got[i], xy[i], tol) << "depth " << depth << " i " << i;
    // Blue holds the reconstructed Z.
    for (size_t t = 0; t < w * h; ++t) {
      const float z = std::sqrt(std::max(0.f, 1.f - xy[2 * t] * xy[2 * t] - xy[2 * t + 1] * xy[2 * t + 1]));
      EXPECT_NEAR(float(back.samples[3 * t + 2]) / float(im.maxValue()) * 2.f - 1.f, z, 2.f * tol);
    }
  }
  // Out of range and NaN inputs are clamped / zeroed, never garbage.
  std::vector<float> bad = {2.f, -3.f, std::nanf(""), 0.f};
  const auto dec = io::decodeNormalMap(io::encodeNormalMap(2, 1, bad, 16), "memory");
  EXPECT_NEAR(dec[0], 1.f, 1e-4f);
  EXPECT_NEAR(dec[1], -1.f, 1e-4f);
  EXPECT_NEAR(dec[2], 0.f, 1e-4f);
}

TEST(Png, ReadErrorsNameTheFile) {
  const test::TempDir tmp("test_png_errors");
  const auto dir = tmp.path();
  const auto missing = dir / "missing.png";
  try {
    io::readPng(missing);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  // Not a PNG.
  const auto text = dir / "text.png";
  std::ofstream(text) << "hello, not an image";
  EXPECT_THROW(io::readPng(text), Error);
  // A valid PNG cut short / with a corrupted data stream.
  Rng rng(test::testSeed(303));
  std::vector<uint8_t> bytes = io::encodePng(randomImage(rng, 40, 40, 3, 16));
  for (size_t cut : {size_t(20), bytes.size() / 2, bytes.size() - 13}) {
    const auto truncated = dir / ("cut" + std::to_string(cut) + ".png");
    std::ofstream(truncated, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(cut));
    try {
      io::readPng(truncated);
      FAIL() << "expected an error for a PNG cut at " << cut;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(truncated.filename().string()), std::string::npos) << e.what();
    }
  }
}

TEST(Png, RejectsInconsistentImages) {
  io::PngImage im;
  im.width = 4, im.height = 4, im.channels = 3, im.bitDepth = 8;
  im.samples.assign(4 * 4 * 3 - 1, 0);
  EXPECT_THROW(io::encodePng(im), Error);  // wrong sample count
  im.samples.assign(4 * 4 * 3, 0);
  im.samples[5] = 300;
  EXPECT_THROW(io::encodePng(im), Error);  // does not fit 8 bits
  im.samples[5] = 0;
  im.bitDepth = 12;
  EXPECT_THROW(io::encodePng(im), Error);
  im.bitDepth = 8;
  im.channels = 5;
  EXPECT_THROW(io::encodePng(im), Error);
  io::PngImage gray;
  gray.width = 1, gray.height = 1, gray.channels = 1, gray.bitDepth = 8, gray.samples = {3};
  EXPECT_THROW(io::decodeNormalMap(gray, "gray"), Error);  // needs X and Y
}
