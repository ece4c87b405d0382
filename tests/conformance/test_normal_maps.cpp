// Conformance of the normal-map kernels to their CPU references: VQ decode (shaders/vq_decode.comp,
// runtime::referenceVqDecode) must be EXACT (it is a lossless gather of snorm8 bytes); the temporal
// blend (shaders/normal_map_blend.comp, runtime::referenceNormalBlend) must match within 1 LSB of
// snorm16, because Vulkan lets a device round float -> snorm to either neighbour; alpha = 0 and 1 are
// exact. Seeded random databases (seed printed; SWISH_TEST_SEED overrides), odd sizes, maps selected
// several times, out-of-range indices, guard words and unchanged inputs.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ostream>

#include "support/gpu_buffers.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/gpu/normal_map_blend_pass.hpp"
#include "swish/gpu/normal_map_images.hpp"
#include "swish/gpu/vq_decode_pass.hpp"
#include "swish/runtime/reference_normal_blend.hpp"
#include "swish/runtime/reference_vq_decode.hpp"

namespace swish {
namespace {

using test::CheckedInput;
using test::GuardedOutput;

NormalMapDatabase randomDatabase(Rng& rng, uint32_t size, uint32_t maps, uint32_t codebook) {
  test::RandomModelSpec spec;
  spec.vertices = 4;
  spec.normalMaps = maps;
  spec.mapSize = size;
  spec.codebookSize = codebook;
  NormalMapDatabase db = test::makeRandomModel(rng, spec).normalMaps;
  for (auto& c : db.codebook) c = int8_t(int(rng.below(256)) - 128);  // every snorm8 value, -128 included
  return db;
}

// Decodes map slotMaps[s] into slot s on the GPU, by jobs in the order `jobOrder` (a permutation of
// the slots; empty: slot order, without a job-slot list); returns the decoded texels as snorm8 pairs.
std::vector<int8_t> gpuDecode(gpu::Context& ctx, const NormalMapDatabase& db, const std::vector<uint32_t>& slotMaps,
                              std::vector<std::string>& problems, const std::vector<uint32_t>& jobOrder = {}) {
  std::vector<int8_t> cb(db.codebook);
  cb.resize((cb.size() + 3) / 4 * 4, 0);
  std::vector<uint16_t> idx(db.indices);
  idx.resize((idx.size() + 1) / 2 * 2, 0);
  CheckedInput codebook(ctx, std::span<const int8_t>(cb), "codebook");
  CheckedInput indices(ctx, std::span<const uint16_t>(idx), "indices");
  std::vector<uint32_t> jobMaps = slotMaps, jobSlots = jobOrder;
  for (size_t j = 0; j < jobOrder.size(); ++j) jobMaps[j] = slotMaps[jobOrder[j]];
  if (jobSlots.empty()) jobSlots.push_back(0);  // a valid buffer, unused
  CheckedInput maps(ctx, std::span<const uint32_t>(jobMaps), "job maps");
  CheckedInput slots(ctx, std::span<const uint32_t>(jobSlots), "job slots");
  const size_t bytes = slotMaps.size() * db.width * db.height * 2;
  GuardedOutput out(ctx, bytes, "decoded maps");
  const gpu::VqDecodePass pass(ctx);
  gpu::VqDecodePass::Args a;
  a.codebook = codebook.address();
  a.indices = indices.address();
  a.jobMaps = maps.address();
  a.jobSlots = jobOrder.empty() ? 0 : slots.address();
  a.decodedOut = out.address();
  a.width = db.width;
  a.height = db.height;
  a.jobCount = uint32_t(slotMaps.size());
  a.codebookSize = db.codebookSize;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });
  auto texels = out.read<int8_t>(ctx);
  texels.resize(bytes);
  for (const CheckedInput* c : {&codebook, &indices, &maps, &slots})
    if (auto s = c->unchanged(ctx); !s.empty()) problems.push_back(s);
  if (auto s = out.guardsIntact(ctx); !s.empty()) problems.push_back(s);
  return texels;
}

void expectDecodeExact(gpu::Context& ctx, const NormalMapDatabase& db, const std::vector<uint32_t>& slotMaps,
                       const std::vector<uint32_t>& jobOrder = {}) {
  std::vector<std::string> problems;
  const auto gpu = gpuDecode(ctx, db, slotMaps, problems, jobOrder);
  for (const auto& p : problems) ADD_FAILURE() << p;
  const size_t per = size_t(db.width) * db.height * 2;
  for (size_t s = 0; s < slotMaps.size(); ++s) {
    const auto ref = runtime::referenceVqDecode(db, slotMaps[s]);
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < per; ++i)
      if (gpu[s * per + i] != ref.xy[i] && bad++ == 0) first = i;
    EXPECT_EQ(bad, 0u) << "slot " << s << " (map " << slotMaps[s] << "): " << bad << " bytes differ, first at texel "
                       << first / 2 << " (gpu " << int(gpu[s * per + first]) << ", reference " << int(ref.xy[first])
                       << ")";
  }
}

struct DecodeCase {
  uint32_t size, maps, codebook;
  std::vector<uint32_t> slots;
};
void PrintTo(const DecodeCase& c, std::ostream* os) {
  *os << c.size << "x" << c.size << ", " << c.maps << " maps, " << c.codebook << " codebook entries, " << c.slots.size()
      << " slots";
}

class VqDecodeConformance : public test::GpuTest, public ::testing::WithParamInterface<DecodeCase> {};

TEST_P(VqDecodeConformance, DecodesExactlyLikeReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x7D + GetParam().size);
  Rng rng(seed);
  const auto db = randomDatabase(rng, GetParam().size, GetParam().maps, GetParam().codebook);
  expectDecodeExact(ctx(), db, GetParam().slots);
  // Jobs writing slots out of order (the frame recorder decodes only new maps, into free slots).
  std::vector<uint32_t> reversed(GetParam().slots.size());
  for (size_t j = 0; j < reversed.size(); ++j) reversed[j] = uint32_t(reversed.size() - 1 - j);
  expectDecodeExact(ctx(), db, GetParam().slots, reversed);
}

// 4x4 (one block), 12x20 (odd block counts), the paper's 360x360 with 8 slots; a codebook of 1 entry and
// one of 65536 (every 16-bit index value usable); an odd index count (word padding).
INSTANTIATE_TEST_SUITE_P(Sizes, VqDecodeConformance,
                         ::testing::Values(DecodeCase{4, 1, 1, {0}}, DecodeCase{12, 3, 7, {2, 0, 1}},
                                           DecodeCase{20, 5, 65536, {4, 4, 1}},
                                           DecodeCase{360, 16, 4096, {0, 3, 5, 7, 9, 11, 13, 15}}),
                         [](const auto& info) {
                           return "S" + std::to_string(info.param.size) + "_C" + std::to_string(info.param.codebook) +
                                  "_Slots" + std::to_string(info.param.slots.size());
                         });

class NormalMapSpecialCases : public test::GpuTest {};

// Indices beyond the codebook (impossible in a validated model) decode to 0 on both sides instead of
// reading out of bounds.
TEST_F(NormalMapSpecialCases, IndexBeyondCodebookDecodesToZero) {
  Rng rng(test::testSeed(0x0B));
  auto db = randomDatabase(rng, 8, 2, 5);
  db.indices[1] = 5;
  db.indices[6] = 65535;
  expectDecodeExact(ctx(), db, {0, 1});
  EXPECT_EQ(runtime::referenceVqDecode(db, 0).xy[2 * 4], 0);  // texel (4,0) is in block 1
}

// The blend of decoded slots into per-character layers: random previous maps, alphas and decoded
// bytes (every snorm8 value), square and not (the kernel walks 4x4 blocks: width and height must not
// be mixed up), one to several blocks across.
TEST_F(NormalMapSpecialCases, BlendMatchesReferenceWithinOneSnorm16Step) {
  SWISH_TEST_SEED_SCOPE(seed, 0xB1E);
  Rng rng(seed);
  if (!ctx().supportsNormalMaps()) GTEST_SKIP() << "device lacks RG16_SNORM storage images";
  // 12 .. 4 texels wide: fewer block columns than the pass's smallest exact workgroup (the bounds-checked
  // form); 64 and 72 wide: 16 and 18 block columns, covered exactly. Heights 4, 8 and 12 run 4 or 8
  // rows per invocation, 48 runs 16 (NormalMapBlendPass::kRowsPerInvocation).
  // Both shaders: 32-bit stores, and 64-bit ones where the device has shaderInt64.
  // Both outputs: a buffer copied into the images, and images that share the blend's output (where the
  // device allows it: then no copy).
  for (const bool shared : {false, true})
    for (const bool store64 : {false, true})
      for (const auto& [width, height] :
           {std::pair<uint32_t, uint32_t>{12, 12}, {20, 8}, {4, 4}, {64, 8}, {72, 12}, {8, 48}}) {
        SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + (store64 ? ", 64-bit stores" : "") +
                     (shared ? ", shared texels" : ""));
        const gpu::NormalMapBlendPass pass(ctx(), width, store64);
        EXPECT_EQ(pass.exact(), width >= 64);
        EXPECT_EQ(pass.stores64(), store64 && ctx().hasShaderInt64());
        const uint32_t characters = 5, slots = 2;
        const size_t per = size_t(width) * height * 2;
        std::vector<runtime::DecodedNormalMap> decoded(slots, {width, height, std::vector<int8_t>(per)});
        std::vector<int8_t> decodedAll;
        for (auto& d : decoded) {
          for (auto& b : d.xy) b = int8_t(int(rng.below(256)) - 128);
          decodedAll.insert(decodedAll.end(), d.xy.begin(), d.xy.end());
        }
        // Characters 0..4: slots and alphas, including alpha 0 (keep prev) and 1 (take decoded).
        const std::vector<gpu::NormalMapBlendPass::Character> chars = {
            {0, 0.f}, {1, 1.f}, {0, 0.37f}, {1, float(rng.uniform())}, {0, 0.5f}};
        std::vector<runtime::BlendedNormalMap> prev;
        std::vector<int16_t> prevAll;
        for (uint32_t c = 0; c < characters; ++c) {
          auto m = runtime::BlendedNormalMap::zeros(width, height);
          for (auto& v : m.xy) v = int16_t(int(rng.below(65535)) - 32767);
          prevAll.insert(prevAll.end(), m.xy.begin(), m.xy.end());
          prev.push_back(std::move(m));
        }
        CheckedInput decodedIn(ctx(), std::span<const int8_t>(decodedAll), "decoded");
        CheckedInput charsIn(ctx(), std::span<const gpu::NormalMapBlendPass::Character>(chars), "characters");
        CheckedInput prevIn(ctx(), std::span<const int16_t>(prevAll), "previous maps");
        GuardedOutput outTexels(ctx(), prevAll.size() * sizeof(int16_t), "blended maps");
        // One layer more than characters: the blend (or its copy into the images) must write the
        // characters' layers only.
        gpu::NormalMapImages outImg(ctx(), width, height, characters + 1, shared);
        if (shared && !outImg.sharesTexels()) continue;  // the device does not allow it: only the copy form runs
        const gpu::Buffer& out = shared ? outImg.texels() : outTexels.buffer();
        {
          const auto binding = pass.makeBinding(ctx(), prevIn.buffer(), out, decodedIn.buffer());
          gpu::NormalMapBlendPass::Args a;
          a.characters = charsIn.address();
          a.width = width;
          a.height = height;
          a.characterCount = characters;
          a.outTexels = out.handle();
          a.outMaps = outImg.image();
          a.outMapsShareTexels = shared;
          ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, binding.get(), a); });
        }
        for (const CheckedInput* c : {&decodedIn, &charsIn, &prevIn})
          if (auto s = c->unchanged(ctx()); !s.empty())
            ADD_FAILURE() << s;  // the previous maps too: read, never written
        const auto images = outImg.download(ctx());
        const std::vector<int16_t> blended(images.begin(), images.begin() + std::ptrdiff_t(characters * per));
        if (!shared) {
          if (auto s = outTexels.guardsIntact(ctx()); !s.empty()) ADD_FAILURE() << s;
          EXPECT_EQ(outTexels.read<int16_t>(ctx()), blended) << "the images must hold a copy of the blended texels";
        }
        EXPECT_EQ(std::vector<int16_t>(images.begin() + std::ptrdiff_t(characters * per), images.end()),
                  std::vector<int16_t>(per, 0))
            << "a layer beyond the characters was written";
        for (uint32_t c = 0; c < characters; ++c) {
          runtime::BlendedNormalMap ref = prev[c];
          runtime::referenceNormalBlend(ref, decoded[chars[c].decodedSlot], chars[c].alpha);
          const bool exact = chars[c].alpha == 0.f || chars[c].alpha == 1.f;
          int maxDiff = 0;
          for (size_t i = 0; i < per; ++i)
            maxDiff = std::max(maxDiff, std::abs(int(blended[c * per + i]) - int(ref.xy[i])));
          EXPECT_LE(maxDiff, exact ? 0 : 1) << "character " << c << " (alpha " << chars[c].alpha << ")";
        }
      }
}

// Characters naming their layers (FrameRecorder leaves out the instances without a map this frame): 3
// characters blend layers 4, 1 and 2 of 6, out of order (runs of one and two layers for the copy into
// the images). Each matches the reference blend of ITS layer's previous map; every other layer is
// neither written in the blend's output nor in the images (those of the copy form still hold the
// output's unwritten marker, the images their zeros). Exact and bounds-checked dispatches, both outputs.
TEST_F(NormalMapSpecialCases, BlendWritesOnlyTheLayersItsCharactersName) {
  SWISH_TEST_SEED_SCOPE(seed, 0x1A7E5);
  Rng rng(seed);
  if (!ctx().supportsNormalMaps()) GTEST_SKIP() << "device lacks RG16_SNORM storage images";
  for (const bool shared : {false, true})
    for (const auto& [width, height] : {std::pair<uint32_t, uint32_t>{64, 8}, {12, 12}}) {
      SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + (shared ? ", shared texels" : ""));
      const gpu::NormalMapBlendPass pass(ctx(), width);
      const uint32_t layers = 6;
      const size_t per = size_t(width) * height * 2;
      std::vector<runtime::DecodedNormalMap> decoded(2, {width, height, std::vector<int8_t>(per)});
      std::vector<int8_t> decodedAll;
      for (auto& d : decoded) {
        for (auto& b : d.xy) b = int8_t(int(rng.below(256)) - 128);
        decodedAll.insert(decodedAll.end(), d.xy.begin(), d.xy.end());
      }
      const std::vector<gpu::NormalMapBlendPass::Character> chars = {{1, 0.25f}, {0, 1.f}, {1, float(rng.uniform())}};
      const std::vector<uint32_t> charLayers = {4, 1, 2};
      std::vector<runtime::BlendedNormalMap> prev;
      std::vector<int16_t> prevAll;
      for (uint32_t l = 0; l < layers; ++l) {
        auto m = runtime::BlendedNormalMap::zeros(width, height);
        for (auto& v : m.xy) v = int16_t(int(rng.below(65535)) - 32767);
        prevAll.insert(prevAll.end(), m.xy.begin(), m.xy.end());
        prev.push_back(std::move(m));
      }
      CheckedInput decodedIn(ctx(), std::span<const int8_t>(decodedAll), "decoded");
      CheckedInput charsIn(ctx(), std::span<const gpu::NormalMapBlendPass::Character>(chars), "characters");
      CheckedInput layersIn(ctx(), std::span<const uint32_t>(charLayers), "layers");
      CheckedInput prevIn(ctx(), std::span<const int16_t>(prevAll), "previous maps");
      GuardedOutput outTexels(ctx(), prevAll.size() * sizeof(int16_t), "blended maps");
      gpu::NormalMapImages outImg(ctx(), width, height, layers, shared);
      if (shared && !outImg.sharesTexels()) continue;  // the device does not allow it: only the copy form runs
      const gpu::Buffer& out = shared ? outImg.texels() : outTexels.buffer();
      {
        const auto binding = pass.makeBinding(ctx(), prevIn.buffer(), out, decodedIn.buffer());
        gpu::NormalMapBlendPass::Args a;
        a.characters = charsIn.address();
        a.layers = layersIn.address();
        a.hostLayers = charLayers;
        a.maxLayers = layers;
        a.width = width;
        a.height = height;
        a.characterCount = uint32_t(chars.size());
        a.outTexels = out.handle();
        a.outMaps = outImg.image();
        a.outMapsShareTexels = shared;
        ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, binding.get(), a); });
      }
      for (const CheckedInput* c : {&decodedIn, &charsIn, &layersIn, &prevIn})
        if (auto s = c->unchanged(ctx()); !s.empty()) ADD_FAILURE() << s;
      const auto images = outImg.download(ctx());
      std::vector<int16_t> texels;
      if (!shared) {
        if (auto s = outTexels.guardsIntact(ctx()); !s.empty()) ADD_FAILURE() << s;
        texels = outTexels.read<int16_t>(ctx());
      }
      for (uint32_t l = 0; l < layers; ++l) {
        const auto layerOf = [&](const std::vector<int16_t>& all) {
          return std::vector<int16_t>(all.begin() + std::ptrdiff_t(l * per),
                                      all.begin() + std::ptrdiff_t((l + 1) * per));
        };
        const std::vector<int16_t> image = layerOf(images);
        const auto c = size_t(std::find(charLayers.begin(), charLayers.end(), l) - charLayers.begin());
        if (c == charLayers.size()) {
          EXPECT_EQ(image, std::vector<int16_t>(per, 0)) << "layer " << l << " of no character was written";
          if (!shared) {
            std::vector<int16_t> unwritten(per);  // the marker GuardedOutput fills its words with
            const uint32_t marker = GuardedOutput::kUnwritten;
            for (size_t i = 0; i < per; i += 2) std::memcpy(&unwritten[i], &marker, 4);
            EXPECT_EQ(layerOf(texels), unwritten) << "layer " << l << " of no character was written in the output";
          }
          continue;
        }
        if (!shared) {
          EXPECT_EQ(layerOf(texels), image) << "layer " << l << ": the images must hold a copy of the blended texels";
        }
        runtime::BlendedNormalMap ref = prev[l];
        runtime::referenceNormalBlend(ref, decoded[chars[c].decodedSlot], chars[c].alpha);
        int maxDiff = 0;
        for (size_t i = 0; i < per; ++i) maxDiff = std::max(maxDiff, std::abs(int(image[i]) - int(ref.xy[i])));
        EXPECT_LE(maxDiff, chars[c].alpha == 1.f ? 0 : 1) << "layer " << l << " (character " << c << ")";
      }
    }
}

}  // namespace
}  // namespace swish
