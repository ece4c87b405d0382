// One whole frame, and a few in a row: every output of gpu::FrameRecorder (deformed positions,
// normals, tangents per instance; per-character normal maps after the temporal blend) against
// runtime::referenceFrame, with two frames in flight so that each frame's blend reads the previous
// frame's maps from the other slot. Tolerances are those of the kernel tests (see test_deform.cpp,
// test_tangent_frames.cpp, test_normal_maps.cpp). Normals and tangents are compared with the reference
// frames of the GPU's OWN deformed positions (the positions are checked on their own): built from the
// reference positions instead, they would carry the skinning tolerance into the frames, amplified where
// a vertex's tangent sum is nearly parallel to its normal (a fixed 2e-4 was exceeded on such a vertex
// by one random stream), so the kernel's own 1e-4 could not be justified.
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

#include "support/error_message.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
#include "support/push_out_tolerance.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/reference_tangent_frames.hpp"

namespace swish {
namespace {

runtime::FrameKernelInputs randomFrameInputs(Rng& rng, const Model& m, uint32_t instances, bool maps) {
  runtime::FrameKernelInputs in;
  in.instanceCount = instances;
  for (int i = 0; i < int(instances) * m.meshComponents(); ++i) in.meshWeights.push_back(float(rng.normal(0, 2)));
  for (uint32_t i = 0; i < instances; ++i) {
    Pose pose = test::makeRandomPose(rng, m.skeleton);
    pose.rootTranslation = Vec3f(rng.uniformf(-50, 50), 0.f, rng.uniformf(-25, 25));  // a football field
    const auto mats = m.skeleton.skinningMatrices(pose);
    in.skinMatrices.insert(in.skinMatrices.end(), mats.begin(), mats.end());
    if (maps) {
      in.selectedMaps.push_back(uint32_t(rng.below(3)));  // few maps: several characters share one
      in.blendAlpha.push_back(float(rng.uniform(0.05, 1.0)));
    }
  }
  return in;
}

// `in`: the frame's inputs (with the push-out on, the positions' tolerance is the push-out's,
// support/push_out_tolerance.hpp, from the reference's positions before it).
void expectFrameMatches(const Model& model, const runtime::FrameKernelInputs& in,
                        const runtime::ReferenceFrameOutputs& gpu, const runtime::ReferenceFrameOutputs& ref,
                        int frame) {
  SCOPED_TRACE("frame " + std::to_string(frame));
  ASSERT_EQ(gpu.positions.size(), ref.positions.size());
  ASSERT_EQ(gpu.normals.size(), ref.normals.size());
  ASSERT_EQ(gpu.normalMaps.size(), ref.normalMaps.size());
  ASSERT_EQ(gpu.normals.size(), gpu.tangents.size());
  const MeshFrameTopology topo = buildFrameTopology(model.gameMesh.triangles, model.gameMesh.positions);
  auto span = [](const auto& m) { return std::span<const float>(m.data(), size_t(m.size())); };
  // The reference's positions before the push-out (its own, in a frame without it).
  runtime::FrameKernelInputs withoutPushOut = in;
  withoutPushOut.pushOut = false;
  const runtime::ReferenceFrameOutputs unpushed = in.pushOut ? runtime::referenceFrame(model, withoutPushOut) : ref;
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    SCOPED_TRACE("instance " + std::to_string(i));
    const auto r = span(ref.positions[i]);
    const size_t j = model.skeleton.size();
    const std::vector<double> tol =
        test::pushOutTolerance(model.bodyAnchors, in.pushOut ? model.bodyAnchors.slots() : 0,
                               std::span(in.skinMatrices).subspan(i * j, j), unpushed.positions[i]);
    EXPECT_TRUE(test::matchesReference("positions", span(gpu.positions[i]), r, [&](size_t e) { return tol[e]; }));
    if (i < gpu.normals.size()) {
      const runtime::ReferenceTangentFrames own =
          runtime::referenceTangentFrames(gpu.positions[i], model.gameMesh, topo);
      constexpr double kFrameTolerance = 1e-4;  // test_tangent_frames.cpp says why
      EXPECT_TRUE(test::matchesReference("normals", span(gpu.normals[i]), span(own.normals),
                                         [](size_t) { return kFrameTolerance; }));
      EXPECT_TRUE(test::matchesReference("tangents", span(gpu.tangents[i]), span(own.tangents),
                                         [](size_t) { return kFrameTolerance; }));
    }
  }
  for (size_t i = 0; i < ref.normalMaps.size(); ++i) {
    int maxDiff = 0;
    for (size_t t = 0; t < ref.normalMaps[i].xy.size(); ++t)
      maxDiff = std::max(maxDiff, std::abs(int(gpu.normalMaps[i].xy[t]) - int(ref.normalMaps[i].xy[t])));
    // 1 LSB of snorm16 per blend; the maps carry one blend per frame, so up to frame + 1 LSB.
    EXPECT_LE(maxDiff, frame + 1) << "normal map of instance " << i;
  }
}

class WholeFrame : public test::GpuTest {};

TEST_F(WholeFrame, GpuFramesMatchReferenceFramesAcrossFramesInFlight) {
  SWISH_TEST_SEED_SCOPE(seed, 0xF4A3E);
  Rng modelRng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 311;
  spec.meshComponents = 30;
  spec.influences = 4;
  spec.normalMaps = 6;
  spec.mapSize = 24;
  spec.codebookSize = 40;
  spec.bodyAnchors = true;  // the push-out inside the deform pass, on in frames 0 and 2, off in frame 1
  const Model model = test::makeRandomModel(modelRng, spec);
  const uint32_t instances = 22;
  gpu::GpuModel gpuModel(ctx(), model, "random model");
  // The normal maps written straight into images that share the blend's output (where the device
  // allows it: lavapipe does), and copied into images of their own.
  for (const bool share : {true, false}) {
    SCOPED_TRACE(share ? "shared texels" : "copied texels");
    Rng rng(seed + 1);  // the same frames for both
    gpu::FrameRecorderOptions options;
    options.framesInFlight = 2;
    options.shareNormalMapTexels = share;
    gpu::FrameRecorder recorder(ctx(), gpuModel, instances, options);
    if (!share) {
      EXPECT_FALSE(recorder.frame(0).normalMaps.sharesTexels());
    }

    std::vector<runtime::BlendedNormalMap> prevMaps;  // reference state; starts at zeros like the GPU images
    for (int frame = 0; frame < 3; ++frame) {
      auto in = randomFrameInputs(rng, model, instances, true);
      in.pushOut = frame != 1;
      ctx().submitAndWait([&](VkCommandBuffer cmd) { recorder.record(cmd, uint64_t(frame), in); });
      const uint32_t slot = recorder.slotOf(uint64_t(frame));
      const auto gpu = recorder.download(slot);
      const auto ref = runtime::referenceFrame(model, in, prevMaps);
      expectFrameMatches(model, in, gpu, ref, frame);
      // Each selected map decoded once, however many characters chose it, and only in the first frame
      // that selects it in this slot.
      const size_t distinct = std::set<uint32_t>(in.selectedMaps.begin(), in.selectedMaps.end()).size();
      EXPECT_EQ(recorder.frame(slot).decodedSlotCount, distinct);
      EXPECT_LE(recorder.frame(slot).decodeJobCount, distinct);
      if (frame < 2) {
        EXPECT_EQ(recorder.frame(slot).decodeJobCount, distinct);
      }
      if (ctx().supportsTimestamps()) {
        const auto t = recorder.stageTimes(slot);
        EXPECT_FALSE(std::isnan(t.deformMs) || std::isnan(t.tangentFramesMs) || std::isnan(t.vqDecodeMs) ||
                     std::isnan(t.normalBlendMs));
        EXPECT_GE(t.totalMs, t.deformMs);
      }
      prevMaps = ref.normalMaps;
    }
  }
}

// Decoded database maps stay in their slots across frames: a frame decodes only the maps no slot holds,
// into the slots selected longest ago (never one the frame reads), and the normal maps still match the
// reference frame after frame while slots are given to other maps.
TEST_F(WholeFrame, DecodedMapsAreKeptAcrossFramesAndTheirSlotsReused) {
  SWISH_TEST_SEED_SCOPE(seed, 0xCAC4E);
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 40;
  spec.normalMaps = 6;
  spec.mapSize = 8;
  spec.codebookSize = 20;
  const Model model = test::makeRandomModel(rng, spec);
  gpu::GpuModel gpuModel(ctx(), model, "random model");
  gpu::FrameRecorder recorder(ctx(), gpuModel, 3, {1, true, true});
  struct Step {
    std::vector<uint32_t> maps;
    int decoded;  // maps the frame must decode (-1: not checked)
  };
  const std::vector<Step> steps = {{{0, 1, 2}, 3},  {{2, 0, 0}, 0}, {{3, 4, 3}, 2},
                                   {{0, 2, 4}, -1}, {{0, 2, 4}, 0}, {{5, 5, 5}, 1}};
  std::vector<runtime::BlendedNormalMap> prevMaps;
  for (size_t f = 0; f <= steps.size(); ++f) {
    if (f == steps.size()) recorder.forgetDecodedMaps();  // then the last frame again: everything decoded anew
    const Step& step = steps[std::min(f, steps.size() - 1)];
    auto in = randomFrameInputs(rng, model, 3, true);
    in.selectedMaps = step.maps;
    ctx().submitAndWait([&](VkCommandBuffer cmd) { recorder.record(cmd, f, in); });
    const auto ref = runtime::referenceFrame(model, in, prevMaps);
    expectFrameMatches(model, in, recorder.download(0), ref, int(f));
    const auto& fr = recorder.frame(0);
    EXPECT_EQ(fr.decodedSlotCount, std::set<uint32_t>(step.maps.begin(), step.maps.end()).size()) << "frame " << f;
    if (f == steps.size()) {
      EXPECT_EQ(fr.decodeJobCount, 1u) << "after forgetDecodedMaps";
    } else if (step.decoded >= 0) {
      EXPECT_EQ(fr.decodeJobCount, uint32_t(step.decoded)) << "frame " << f;
    }
    prevMaps = ref.normalMaps;
  }
}

// Quality levels per instance (runtime::defaultLadder: full and k15 with maps; k7, k3 and the mean shape
// without), in the same dispatches: each instance's k (with garbage in its weights beyond k), and
// kNoMap for the levels without maps. Those instances get no decode and no blend, and their normal
// maps must stay bit for bit what the GPU had after the previous frame (and equal the reference's,
// which hands prevMaps back), across two frames in flight (their layers come from the other slot, a
// copy only when the slot's layer is older) and with one; every other output matches the reference
// as in the tests above. Frame 3 has no instance with a map (no decode or blend dispatch at all); before
// it, a frame recorded into a command buffer that is thrown away (then forgetDecodedMaps) must not
// make the recorder believe its layers were written.
TEST_F(WholeFrame, QualityLevelsPerInstanceMatchReferenceAndKeepMapsOfLevelsWithoutThem) {
  SWISH_TEST_SEED_SCOPE(seed, 0x1E7E15);
  Rng modelRng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 311;
  spec.meshComponents = 30;
  spec.normalMaps = 6;
  spec.mapSize = 24;
  spec.codebookSize = 40;
  spec.bodyAnchors = true;
  const Model model = test::makeRandomModel(modelRng, spec);
  const runtime::QualityLadder ladder = runtime::defaultLadder(model);
  ASSERT_EQ(ladder.size(), 5u);
  ASSERT_TRUE(ladder[1].normalMaps && !ladder[2].normalMaps);
  const uint32_t instances = 22;
  gpu::GpuModel gpuModel(ctx(), model, "random model");
  // Per frame, each instance's level: frame 0 all full (every layer gets a map); instance 0 then stays
  // without maps, instance 1 alternates, the rest are drawn; frame 3 all without maps.
  Rng levelRng(seed + 2);
  std::vector<std::vector<size_t>> levels(6, std::vector<size_t>(instances, 0));
  for (size_t f = 1; f < levels.size(); ++f)
    for (uint32_t i = 0; i < instances; ++i)
      levels[f][i] = i == 0 ? 4 : i == 1 ? (f % 2 ? 2 : 1) : f == 3 ? 2 + levelRng.below(3) : levelRng.below(5);
  for (const uint32_t framesInFlight : {2u, 1u})
    for (const bool share : {true, false}) {
      SCOPED_TRACE(std::to_string(framesInFlight) + " frames in flight, " +
                   (share ? "shared texels" : "copied texels"));
      Rng rng(seed + 1);  // the same frames for every recorder
      gpu::FrameRecorderOptions options;
      options.framesInFlight = framesInFlight;
      options.shareNormalMapTexels = share;
      gpu::FrameRecorder recorder(ctx(), gpuModel, instances, options);
      std::vector<runtime::BlendedNormalMap> prevMaps, prevGpuMaps;
      std::vector<int> lastBlended(instances, -1);
      uint32_t fullDispatches = 0;
      for (int frame = 0; frame < int(levels.size()); ++frame) {
        SCOPED_TRACE("frame " + std::to_string(frame));
        auto in = randomFrameInputs(rng, model, instances, true);
        std::vector<uint32_t> kept;
        for (uint32_t i = 0; i < instances; ++i) {
          const runtime::QualityLevel& level = ladder[levels[size_t(frame)][i]];
          in.meshComponents.push_back(level.meshComponents);
          for (int c = int(level.meshComponents); c < model.meshComponents(); ++c)
            in.meshWeights[size_t(i) * size_t(model.meshComponents()) + size_t(c)] =
                std::numeric_limits<float>::quiet_NaN();  // must be ignored
          if (!level.normalMaps) {
            in.selectedMaps[i] = runtime::kNoMap;
            kept.push_back(i);
          }
        }
        if (frame == 3) {  // thrown away: blends every instance, its layers never written
          auto lost = randomFrameInputs(rng, model, instances, true);
          VkCommandBuffer cmd = ctx().beginOneTime();
          recorder.record(cmd, uint64_t(frame), lost);
          ctx().abandonOneTime(cmd);
          recorder.forgetDecodedMaps();
        }
        uint32_t dispatches = 0;
        ctx().submitAndWait([&](VkCommandBuffer cmd) { dispatches = recorder.record(cmd, uint64_t(frame), in); });
        const uint32_t slot = recorder.slotOf(uint64_t(frame));
        const auto gpu = recorder.download(slot);
        const auto ref = runtime::referenceFrame(model, in, prevMaps);
        expectFrameMatches(model, in, gpu, ref, frame);
        for (uint32_t i : kept) {
          EXPECT_EQ(gpu.normalMaps[i].xy,
                    prevGpuMaps.empty() ? std::vector<int16_t>(gpu.normalMaps[i].xy.size(), 0) : prevGpuMaps[i].xy)
              << "instance " << i << " has no map this frame: its map must stay as it was";
          EXPECT_EQ(ref.normalMaps[i].xy, prevMaps[i].xy) << "reference, instance " << i;
        }
        const gpu::FrameResources& fr = recorder.frame(slot);
        EXPECT_EQ(fr.blendedCount, instances - kept.size());
        // A kept layer is copied only where the other slot holds a newer map: after a blend in the
        // frame before, or after forgetDecodedMaps (frame 3); never with one frame in flight.
        uint32_t copies = 0;
        for (uint32_t i : kept) copies += framesInFlight > 1 && (lastBlended[i] == frame - 1 || frame == 3);
        EXPECT_EQ(fr.carriedLayers, copies);
        if (frame == 0) fullDispatches = dispatches;
        if (kept.size() == instances) {
          EXPECT_EQ(dispatches, fullDispatches - 2) << "no decode and no blend without a map";
          EXPECT_EQ(fr.decodeJobCount, 0u);
          if (ctx().supportsTimestamps()) {
            EXPECT_TRUE(std::isnan(recorder.stageTimes(slot).vqDecodeMs));
            EXPECT_TRUE(std::isnan(recorder.stageTimes(slot).normalBlendMs));
          }
        }
        for (uint32_t i = 0; i < instances; ++i)
          if (in.selectedMaps[i] != runtime::kNoMap) lastBlended[i] = frame;
        prevMaps = ref.normalMaps;
        prevGpuMaps = gpu.normalMaps;
      }
    }
}

TEST_F(WholeFrame, ModelWithoutNormalMapsRecordsOnlyMeshWork) {
  SWISH_TEST_SEED_SCOPE(seed, 0x40AB);
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 53;
  spec.normalMaps = 0;
  const Model model = test::makeRandomModel(rng, spec);
  gpu::GpuModel gpuModel(ctx(), model);
  gpu::FrameRecorder recorder(ctx(), gpuModel, 3, {1, true, true});
  const auto in = randomFrameInputs(rng, model, 3, false);
  ctx().submitAndWait([&](VkCommandBuffer cmd) { recorder.record(cmd, 0, in); });
  const auto gpu = recorder.download(0);
  EXPECT_TRUE(gpu.normalMaps.empty());
  expectFrameMatches(model, in, gpu, runtime::referenceFrame(model, in), 0);
  if (ctx().supportsTimestamps()) {
    EXPECT_TRUE(std::isnan(recorder.stageTimes(0).vqDecodeMs));
  }
  // What a frame evaluator hands over for a model without a database: kNoMap for every instance.
  auto noMaps = in;
  noMaps.selectedMaps.assign(3, runtime::kNoMap);
  noMaps.blendAlpha.assign(3, 0.f);
  ctx().submitAndWait([&](VkCommandBuffer cmd) { recorder.record(cmd, 1, noMaps); });
  const auto again = recorder.download(0);
  EXPECT_TRUE(again.normalMaps.empty());
  expectFrameMatches(model, noMaps, again, runtime::referenceFrame(model, noMaps), 0);
}

TEST_F(WholeFrame, BadInputsAreRejectedWithAReason) {
  Rng rng(3);
  const Model model = test::makeRandomModel(rng, {});
  gpu::GpuModel gpuModel(ctx(), model);
  gpu::FrameRecorder recorder(ctx(), gpuModel, 2);
  auto in = randomFrameInputs(rng, model, 2, true);
  in.selectedMaps[1] = 99;
  VkCommandBuffer cmd = ctx().beginOneTime();
  EXPECT_THROW(recorder.record(cmd, 0, in), Error);
  in = randomFrameInputs(rng, model, 3, true);
  EXPECT_THROW(recorder.record(cmd, 0, in), Error);  // beyond the capacity of 2
  in = randomFrameInputs(rng, model, 2, true);
  in.meshComponents = {uint32_t(model.meshComponents()) + 1, 0};
  EXPECT_NE(test::errorOf([&] { recorder.record(cmd, 0, in); }).find("instance 0 reads"), std::string::npos);
  in.meshComponents = {1};
  EXPECT_NE(test::errorOf([&] { recorder.record(cmd, 0, in); }).find("1 per-instance mesh component counts"),
            std::string::npos);
  ctx().abandonOneTime(cmd);
}

}  // namespace
}  // namespace swish
