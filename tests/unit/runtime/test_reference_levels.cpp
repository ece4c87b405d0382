// The CPU reference at quality levels (runtime/quality_levels.hpp), the specification the GPU kernels
// conform to (tests/conformance/test_deform.cpp, test_whole_frame.cpp): an instance at k components
// reconstructs from its first k weights only (the rest ignored, NaN included), and an instance whose
// selected map is kNoMap keeps its previous normal map exactly.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/reference_pca.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

FrameKernelInputs randomInputs(Rng& rng, const Model& m, uint32_t instances) {
  FrameKernelInputs in;
  in.instanceCount = instances;
  for (int i = 0; i < int(instances) * m.meshComponents(); ++i) in.meshWeights.push_back(float(rng.normal(0, 2)));
  for (uint32_t i = 0; i < instances; ++i) {
    const auto mats = m.skeleton.skinningMatrices(test::makeRandomPose(rng, m.skeleton));
    in.skinMatrices.insert(in.skinMatrices.end(), mats.begin(), mats.end());
    in.selectedMaps.push_back(uint32_t(rng.below(m.normalMaps.mapCount())));
    in.blendAlpha.push_back(float(rng.uniform(0.1, 1.0)));
  }
  return in;
}

}  // namespace

// The first k terms, in order, from the mean: the full sum with the weights from k on set to zero gives
// the same floats (adding an exact zero changes nothing), whatever the ignored weights hold.
TEST(ReferenceLevels, PcaReadsOnlyTheLeadingComponents) {
  Rng rng(test::announcedTestSeed(0x9CA));
  test::RandomModelSpec spec;
  spec.meshComponents = 9;
  const Model m = test::makeRandomModel(rng, spec);
  std::vector<float> w(9);
  for (auto& x : w) x = float(rng.normal(0, 2));
  for (uint32_t k = 0; k <= 9; ++k) {
    SCOPED_TRACE("k " + std::to_string(k));
    std::vector<float> poisoned = w, zeroed = w;
    for (uint32_t c = k; c < 9; ++c) {
      poisoned[c] = std::numeric_limits<float>::quiet_NaN();
      zeroed[c] = 0.f;
    }
    const Points3f got = referencePcaReconstruct(m.meshPca, poisoned, k);
    const Points3f full = referencePcaReconstruct(m.meshPca, zeroed);
    ASSERT_EQ(got.size(), full.size());
    for (Eigen::Index i = 0; i < got.size(); ++i) ASSERT_EQ(got.data()[i], full.data()[i]) << "value " << i;
    if (k == 0) {
      for (Eigen::Index i = 0; i < got.size(); ++i) ASSERT_EQ(got.data()[i], m.meshPca.mean[i]);
    }
  }
  EXPECT_NE(test::errorOf([&] { referencePcaReconstruct(m.meshPca, w, 10); }).find("10 leading components of 9"),
            std::string::npos);
}

// Per instance k in a frame: each instance's positions are those of the same instance alone with its
// weights beyond k zeroed; kNoMap keeps the previous map bit for bit (zeros without one), the others
// blend as before.
TEST(ReferenceLevels, FrameHonoursPerInstanceComponentsAndNoMap) {
  Rng rng(test::announcedTestSeed(0xF7A));
  test::RandomModelSpec spec;
  spec.meshComponents = 7;
  spec.normalMaps = 5;
  spec.mapSize = 8;
  const Model m = test::makeRandomModel(rng, spec);
  FrameKernelInputs in = randomInputs(rng, m, 4);
  in.meshComponents = {7, 0, 3, 5};
  in.selectedMaps[1] = kNoMap;
  in.selectedMaps[3] = kNoMap;
  FrameKernelInputs zeroed = in;
  zeroed.meshComponents.clear();
  for (uint32_t i = 0; i < 4; ++i)
    for (uint32_t c = in.meshComponents[i]; c < 7; ++c) {
      in.meshWeights[i * 7 + c] = std::numeric_limits<float>::infinity();  // ignored
      zeroed.meshWeights[i * 7 + c] = 0.f;
    }
  std::vector<BlendedNormalMap> prev;
  for (int i = 0; i < 4; ++i) {
    prev.push_back(BlendedNormalMap::zeros(8, 8));
    for (auto& v : prev.back().xy) v = int16_t(int(rng.below(65535)) - 32767);
  }
  const ReferenceFrameOutputs out = referenceFrame(m, in, prev), fromZeros = referenceFrame(m, in);
  const ReferenceFrameOutputs ref = referenceFrame(m, zeroed, prev);
  ASSERT_EQ(out.positions.size(), 4u);
  ASSERT_EQ(out.normalMaps.size(), 4u);
  for (uint32_t i = 0; i < 4; ++i) {
    SCOPED_TRACE("instance " + std::to_string(i));
    EXPECT_TRUE(out.positions[i].isApprox(ref.positions[i], 0.f));
    EXPECT_TRUE(out.positions[i].allFinite());
    EXPECT_TRUE(out.positions[i].isApprox(referencePositions(m, in, i, in.pushOut), 0.f));
    if (in.selectedMaps[i] == kNoMap) {
      EXPECT_EQ(out.normalMaps[i].xy, prev[i].xy);
      EXPECT_EQ(fromZeros.normalMaps[i].xy, std::vector<int16_t>(prev[i].xy.size(), 0));
    } else {
      EXPECT_EQ(out.normalMaps[i].xy, ref.normalMaps[i].xy);
      EXPECT_NE(out.normalMaps[i].xy, prev[i].xy);
    }
  }
}

TEST(ReferenceLevels, ValidateChecksLevelsAndAcceptsNoMap) {
  Rng rng(5);
  test::RandomModelSpec spec;
  spec.meshComponents = 6;
  const Model m = test::makeRandomModel(rng, spec);
  FrameKernelInputs in = randomInputs(rng, m, 3);
  in.selectedMaps = {kNoMap, 0, kNoMap};
  in.meshComponents = {0, 6, 4};
  EXPECT_NO_THROW(in.validate(m));
  in.meshComponents = {0, 7, 4};
  EXPECT_NE(test::errorOf([&] { in.validate(m); }).find("instance 1 reads 7 mesh components; the model has 6"),
            std::string::npos);
  in.meshComponents = {1, 2};
  EXPECT_NE(test::errorOf([&] { in.validate(m); }).find("2 per-instance mesh component counts for 3 instances"),
            std::string::npos);
  in.meshComponents.clear();
  in.selectedMaps[1] = m.normalMaps.mapCount();
  EXPECT_NE(test::errorOf([&] { in.validate(m); }).find("instance 1 selected map"), std::string::npos);
  // A model without a database: kNoMap everywhere is what a frame evaluator hands over; a map is not.
  spec.normalMaps = 0;
  const Model bare = test::makeRandomModel(rng, spec);
  FrameKernelInputs none = randomInputs(rng, m, 2);
  none.selectedMaps = {kNoMap, kNoMap};
  EXPECT_NO_THROW(none.validate(bare));
  EXPECT_TRUE(referenceFrame(bare, none).normalMaps.empty());
  none.selectedMaps = {kNoMap, 0};
  EXPECT_NE(test::errorOf([&] { none.validate(bare); }).find("no normal-map database"), std::string::npos);
}
