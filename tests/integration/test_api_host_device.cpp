// The public embedding API (include/swish/) on a device the HOST made, validation on:
//  - recording into the host's own command buffers across several frames in flight, with the host's
//    fences, and every output equal to the CPU reference frame;
//  - a frame whose resources the GPU may still read is never overwritten (FrameInFlight);
//  - models destroyed and recreated; two runtimes at once (host-made + swish-made device);
//  - errors as values and as exceptions with codes.
// Tolerances: those of the whole-frame conformance test (tests/conformance/test_whole_frame.cpp):
// positions 2e-6 + 1e-5 relative, normals and tangents 2e-4.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "support/api_host_fixture.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_frame.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"  // Vulkan structs: other members zero on purpose

namespace swish {
namespace {

struct HostPoses {
  std::vector<std::vector<api::Quat>> rotations;
  std::vector<api::CharacterPose> poses;
  std::vector<Pose> internal;
  std::vector<Mat4f> worlds;
};

HostPoses randomPoses(Rng& rng, const Model& m, uint32_t characters) {
  HostPoses h;
  h.rotations.resize(characters);
  for (uint32_t c = 0; c < characters; ++c) {
    Pose p = test::makeRandomPose(rng, m.skeleton);
    p.rootTranslation = m.skeleton.joints[0].rest.translation;
    for (const Quatf& q : p.local) h.rotations[c].push_back({q.x(), q.y(), q.z(), q.w()});
    Mat4f world = Mat4f::Identity();
    world.topLeftCorner<3, 3>() = Eigen::AngleAxisf(rng.uniformf(-3, 3), Vec3f::UnitY()).toRotationMatrix();
    world.topRightCorner<3, 1>() = Vec3f(rng.uniformf(-40, 40), 0, rng.uniformf(-20, 20));  // on a pitch
    h.internal.push_back(p);
    h.worlds.push_back(world);
  }
  for (uint32_t c = 0; c < characters; ++c) {
    api::CharacterPose ap;
    ap.localRotations = h.rotations[c];
    std::memcpy(ap.characterToWorld.data(), h.worlds[c].data(), 64);
    ap.dtSeconds = 1.f / 60.f;
    h.poses.push_back(ap);
  }
  return h;
}

// A host's per-frame objects: command buffers and fences of its own.
struct HostFrames {
  VkDevice dev;
  VkCommandPool pool = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> cmds;
  std::vector<VkFence> fences;
  HostFrames(VkDevice d, uint32_t family, uint32_t n) : dev(d), cmds(n), fences(n) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr,
                                VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, family};
    vkCreateCommandPool(dev, &pci, nullptr, &pool);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool,
                                   VK_COMMAND_BUFFER_LEVEL_PRIMARY, n};
    vkAllocateCommandBuffers(dev, &ai, cmds.data());
    for (auto& f : fences) {
      VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, nullptr, VK_FENCE_CREATE_SIGNALED_BIT};
      vkCreateFence(dev, &fci, nullptr, &f);
    }
  }
  ~HostFrames() {
    vkWaitForFences(dev, uint32_t(fences.size()), fences.data(), VK_TRUE, UINT64_MAX);
    for (auto f : fences) vkDestroyFence(dev, f, nullptr);
    vkDestroyCommandPool(dev, pool, nullptr);
  }
  VkCommandBuffer begin(uint32_t slot) {
    vkWaitForFences(dev, 1, &fences[slot], VK_TRUE, UINT64_MAX);
    vkResetFences(dev, 1, &fences[slot]);
    vkResetCommandBuffer(cmds[slot], 0);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmds[slot], &bi);
    return cmds[slot];
  }
  void submit(VkQueue q, uint32_t slot) {
    vkEndCommandBuffer(cmds[slot]);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmds[slot];
    vkQueueSubmit(q, 1, &si, fences[slot]);
  }
  void waitAll() { vkWaitForFences(dev, uint32_t(fences.size()), fences.data(), VK_TRUE, UINT64_MAX); }
};

void expectClose(const std::vector<float>& gpu, const float* ref, size_t n, double abs, double rel, const char* what) {
  ASSERT_EQ(gpu.size(), n) << what;
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i)
    if (!(std::abs(double(gpu[i]) - ref[i]) <= abs + rel * std::abs(double(ref[i])))) {
      if (bad++ < 5) ADD_FAILURE() << what << "[" << i << "]: GPU " << gpu[i] << " vs reference " << ref[i];
    }
  EXPECT_EQ(bad, 0u) << what;
}

Model randomModel(uint64_t seed, uint32_t vertices) {
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = vertices;
  spec.meshComponents = 7;
  spec.normalMaps = 5;
  spec.mapSize = 16;
  spec.noveltyCentres = 4;  // the guard runs: the reference below runs it too (FrameEvaluator)
  return test::makeRandomModel(rng, spec);
}

TEST(ApiHostDevice, RecordsIntoHostCommandBuffersAcrossFramesInFlight) {
  SWISH_HOST_DEVICE_OR_SKIP(device);
  SWISH_TEST_SEED_SCOPE(seed, 0xA71);
  const Model model = randomModel(seed, 157);
  api::Runtime rt = api::Runtime::adopt(device->handles());
  EXPECT_FALSE(rt.ownsDevice());
  api::Model m = rt.loadModelFromMemory(serializeModel(model), "random");
  EXPECT_TRUE(m.info().hasNoveltyGuard);
  EXPECT_EQ(m.info().noveltyFlagAbove, model.noveltyGuard.flagAbove);
  const uint32_t characters = 3, inFlight = 3, frames = 8;
  api::CharacterBatch batch = m.createBatch({characters, inFlight, true});
  HostFrames host(device->device(), device->queueFamily(), inFlight);

  Rng rng(seed + 1);
  runtime::FrameEvaluator cpu(model, characters);  // the CPU reference's own state (filters)
  std::vector<runtime::BlendedNormalMap> prevMaps;
  std::vector<runtime::ReferenceFrameOutputs> refs(frames);
  for (uint64_t f = 0; f < frames; ++f) {
    const uint32_t slot = uint32_t(f % inFlight);
    VkCommandBuffer cmd = host.begin(slot);  // waits for frame f - inFlight's fence
    if (f >= inFlight) batch.retireFrame(f - inFlight);
    const HostPoses poses = randomPoses(rng, model, characters);
    const api::FrameReport report = batch.recordFrame(cmd, f, poses.poses);
    EXPECT_TRUE(report.warnings.empty());
    const api::FrameOutputs out = batch.outputs(f);
    EXPECT_EQ(out.vertexCount, model.gameMesh.vertexCount());
    EXPECT_EQ(out.positions.instanceStride, out.vertexCount * 12u);
    ASSERT_TRUE(out.normalMaps.has_value());
    EXPECT_EQ(out.normalMaps->layout, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_TRUE(out.normalMaps->usage & VK_IMAGE_USAGE_SAMPLED_BIT);
    // The host's own consumer barriers, as the guide says.
    const auto bufs = out.vertexBarriers();
    const auto img = out.normalMapBarrier();
    VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    di.bufferMemoryBarrierCount = uint32_t(bufs.size());
    di.pBufferMemoryBarriers = bufs.data();
    di.imageMemoryBarrierCount = 1;
    di.pImageMemoryBarriers = &*img;
    vkCmdPipelineBarrier2(cmd, &di);
    host.submit(device->queue(), slot);

    // Reference of this frame.
    std::vector<Quatf> rots;
    for (const Pose& p : poses.internal) rots.insert(rots.end(), p.local.begin(), p.local.end());
    const auto& o = cpu.evaluate(rots, 1.f / 60.f);
    // Novelty per instance, as the CPU frame path measures it.
    EXPECT_EQ(report.novelty, o.novelty);
    EXPECT_EQ(report.guardBlend, o.guardBlend);
    EXPECT_EQ(report.novelCharacters, o.novel);
    runtime::FrameKernelInputs in;
    in.instanceCount = characters;
    in.meshWeights = o.meshWeights;
    for (uint32_t c = 0; c < characters; ++c)
      for (const Mat4f& s : model.skeleton.skinningMatrices(poses.internal[c]))
        in.skinMatrices.push_back(poses.worlds[c] * s);
    in.selectedMaps = o.mapIndex;
    in.blendAlpha = o.blendAlpha;
    refs[f] = runtime::referenceFrame(model, in, prevMaps);
    prevMaps = refs[f].normalMaps;
  }
  // Recording over a frame still in flight is refused, and changes nothing.
  {
    VkCommandBuffer cmd = host.cmds[frames % inFlight];
    const HostPoses poses = randomPoses(rng, model, characters);
    try {
      batch.recordFrame(cmd, frames, poses.poses);
      FAIL() << "expected FrameInFlight";
    } catch (const api::Error& e) {
      EXPECT_EQ(e.code(), api::ErrorCode::FrameInFlight) << e.what();
    }
  }
  host.waitAll();
  batch.retireFrame(frames - 1);
  EXPECT_TRUE(batch.idle());
  // The last inFlight frames are still held: each against its reference.
  for (uint64_t f = frames - inFlight; f < frames; ++f)
    for (uint32_t c = 0; c < characters; ++c) {
      SCOPED_TRACE("frame " + std::to_string(f) + " character " + std::to_string(c));
      const api::DeformedMesh g = batch.readBackMesh(f, c);
      const size_t n = model.gameMesh.vertexCount();
      expectClose(g.positions, refs[f].positions[c].data(), 3 * n, 2e-6, 1e-5, "positions");
      expectClose(g.normals, refs[f].normals[c].data(), 3 * n, 2e-4, 0, "normals");
      expectClose(g.tangents, refs[f].tangents[c].data(), 4 * n, 2e-4, 0, "tangents");
      const auto map = batch.readBackNormalMap(f, c);
      ASSERT_EQ(map.size(), refs[f].normalMaps[c].xy.size());
      int maxDiff = 0;
      for (size_t t = 0; t < map.size(); ++t)
        maxDiff = std::max(maxDiff, std::abs(int(map[t]) - int(refs[f].normalMaps[c].xy[t])));
      EXPECT_LE(maxDiff, int(f) + 1) << "1 LSB per blend (see test_whole_frame.cpp)";
    }
  // Older frames are no longer held.
  EXPECT_THROW(batch.outputs(0), api::Error);
  test::expectNoValidationMessages(*device);
}

// Quality levels through the API: the model's ladder in ModelInfo, a host's own level per character
// (the mesh is the CPU reference's at that level), swish's own choice from the camera, range errors.
TEST(ApiHostDevice, QualityLevelsSetByTheHostOrPlannedBySwish) {
  SWISH_HOST_DEVICE_OR_SKIP(device);
  const Model model = randomModel(0x1E7, 60);
  api::Runtime rt = api::Runtime::adopt(device->handles());
  api::Model m = rt.loadModelFromMemory(serializeModel(model), "levels");
  const runtime::QualityLadder ladder = runtime::ladderOf(model);
  ASSERT_EQ(m.info().qualityLevels.size(), ladder.size());
  for (size_t l = 0; l < ladder.size(); ++l) {
    EXPECT_EQ(m.info().qualityLevels[l].name, ladder[l].name);
    EXPECT_EQ(m.info().qualityLevels[l].meshComponents, ladder[l].meshComponents);
  }
  const uint32_t characters = 3, skinned = uint32_t(ladder.size() - 1);
  api::CharacterBatch batch = m.createBatch({characters, 1, true});
  batch.setQualityLevel(1, skinned);
  EXPECT_EQ(batch.qualityLevel(1), skinned);
  EXPECT_EQ(batch.qualityLevel(0), 0u);
  HostFrames host(device->device(), device->queueFamily(), 1);
  Rng rng(5);
  HostPoses poses = randomPoses(rng, model, characters);
  VkCommandBuffer cmd = host.begin(0);
  const api::FrameReport report = batch.recordFrame(cmd, 0, poses.poses);
  host.submit(device->queue(), 0);
  host.waitAll();
  batch.retireFrame(0);
  EXPECT_EQ(report.qualityLevels, (std::vector<uint32_t>{0, skinned, 0}));
  // Character 1 at the skinned level: the mean shape, skinned, whatever the network says.
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.meshWeights.assign(size_t(model.meshComponents()), 0.f);
  for (const Mat4f& sm : model.skeleton.skinningMatrices(poses.internal[1]))
    in.skinMatrices.push_back(poses.worlds[1] * sm);
  const Points3f ref = runtime::referencePositions(model, in, 0, true);
  const api::DeformedMesh mesh = batch.readBackMesh(0, 1);
  expectClose(mesh.positions, ref.data(), size_t(ref.size()), 1e-4, 1e-5, "skinned level positions");
  // swish plans: a character behind the camera runs at the cheapest level, the others where the
  // tolerance puts them (this model's ladder is not measured, so at full quality).
  api::LevelPlanning plan;
  plan.cameraPosition = {0, 1.5f, -100};
  plan.cameraTarget = {0, 1, 0};
  api::CharacterBatch planned = m.createBatch({characters, 1, true});
  planned.planQualityLevels(plan);
  poses.worlds[2].topRightCorner<3, 1>() = Vec3f(0, 0, -200);  // behind the camera
  std::memcpy(poses.poses[2].characterToWorld.data(), poses.worlds[2].data(), 64);
  for (uint32_t c = 0; c < 2; ++c) {
    poses.worlds[c].topRightCorner<3, 1>() = Vec3f(float(c), 0, 0);
    std::memcpy(poses.poses[c].characterToWorld.data(), poses.worlds[c].data(), 64);
  }
  cmd = host.begin(0);
  const api::FrameReport r2 = planned.recordFrame(cmd, 0, poses.poses);
  host.submit(device->queue(), 0);
  host.waitAll();
  planned.retireFrame(0);
  EXPECT_EQ(r2.qualityLevels, (std::vector<uint32_t>{0, 0, skinned}));
  try {
    batch.setQualityLevel(0, uint32_t(ladder.size()));
    ADD_FAILURE() << "a level beyond the ladder was accepted";
  } catch (const api::Error& e) {
    EXPECT_EQ(e.code(), api::ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("of a ladder of"), std::string::npos) << e.what();
  }
  test::expectNoValidationMessages(*device);
}

TEST(ApiHostDevice, ModelsDestroyedAndRecreated) {
  SWISH_HOST_DEVICE_OR_SKIP(device);
  api::Runtime rt = api::Runtime::adopt(device->handles());
  HostFrames host(device->device(), device->queueFamily(), 1);
  Rng rng(77);
  for (int round = 0; round < 3; ++round) {
    const Model model = randomModel(100 + round, 40 + 30 * round);
    api::Model m = rt.loadModelFromMemory(serializeModel(model), "model " + std::to_string(round));
    api::CharacterBatch batch = m.createBatch({2, 2, true});
    for (uint64_t f = 0; f < 2; ++f) {
      VkCommandBuffer cmd = host.begin(0);
      if (f > 0) batch.retireFrame(f - 1);  // its fence was waited on by begin()
      const HostPoses poses = randomPoses(rng, model, 2);
      batch.recordFrame(cmd, f, poses.poses);
      host.submit(device->queue(), 0);
    }
    host.waitAll();
    batch.retireFrame(1);
    EXPECT_TRUE(batch.idle());
    EXPECT_EQ(batch.readBackMesh(1, 1).positions.size(), 3 * model.gameMesh.vertexCount());
  }  // batch and model destroyed here, each round
  test::expectNoValidationMessages(*device);
}

TEST(ApiHostDevice, TwoRuntimesAtOnceGiveTheSameFrames) {
  SWISH_HOST_DEVICE_OR_SKIP(device);
  // One runtime on the host's device, one on a device swish makes itself: independent, no shared state.
  api::Runtime hostRt = api::Runtime::adopt(device->handles());
  api::RuntimeOptions o;
  o.validation = test::hostDeviceOptions().validation;
  auto made = api::Runtime::tryCreate(o);
  ASSERT_TRUE(made.ok()) << made.error().what();
  api::Runtime ownRt = std::move(made).value();
  EXPECT_TRUE(ownRt.ownsDevice());
  EXPECT_NE(ownRt.device().device, hostRt.device().device);
  const Model model = randomModel(5, 90);
  const auto bytes = serializeModel(model);
  api::Model a = hostRt.loadModelFromMemory(bytes, "a");
  api::Model b = ownRt.loadModelFromMemory(bytes, "b");
  api::CharacterBatch ba = a.createBatch({2, 2, true}), bb = b.createBatch({2, 2, true});
  HostFrames hostA(device->device(), device->queueFamily(), 1);
  HostFrames hostB(ownRt.device().device, ownRt.device().queueFamily, 1);
  Rng rng(9);
  for (uint64_t f = 0; f < 3; ++f) {
    const HostPoses poses = randomPoses(rng, model, 2);
    VkCommandBuffer ca = hostA.begin(0), cb = hostB.begin(0);
    if (f > 0) ba.retireFrame(f - 1), bb.retireFrame(f - 1);
    ba.recordFrame(ca, f, poses.poses);
    bb.recordFrame(cb, f, poses.poses);
    hostA.submit(device->queue(), 0);
    hostB.submit(ownRt.device().queue, 0);
  }
  hostA.waitAll();
  hostB.waitAll();
  ba.retireFrame(2);
  bb.retireFrame(2);
  const auto ma = ba.readBackMesh(2, 1), mb = bb.readBackMesh(2, 1);
  EXPECT_EQ(ma.positions, mb.positions) << "same driver, same inputs: the same bits";
  EXPECT_EQ(ba.readBackNormalMap(2, 0), bb.readBackNormalMap(2, 0));
  test::expectNoValidationMessages(*device);
  const auto own = ownRt.validationMessages();
  EXPECT_TRUE(own.empty()) << (own.empty() ? "" : own[0]);
}

TEST(ApiHostDevice, ErrorsComeAsValuesOrExceptionsWithCodes) {
  SWISH_HOST_DEVICE_OR_SKIP(device);
  api::Runtime rt = api::Runtime::adopt(device->handles());
  // A corrupt file: a value with BadModel and the loader's reason.
  std::vector<uint8_t> bytes = serializeModel(randomModel(3, 20));
  bytes[40] ^= 0xFF;
  EXPECT_THROW(rt.loadModelFromMemory(bytes, "corrupt.swish"), api::Error);
  const auto missing = rt.tryLoadModel("/nonexistent/model.swish");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code(), api::ErrorCode::BadModel);
  EXPECT_NE(std::string(missing.error().what()).find("/nonexistent/model.swish"), std::string::npos);
  // Adoption without handles.
  const auto none = api::Runtime::tryAdopt({});
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code(), api::ErrorCode::InvalidArgument);

  const Model model = randomModel(4, 20);
  api::Model m = rt.loadModelFromMemory(serializeModel(model), "m");
  EXPECT_THROW(m.createBatch({0, 2, true}), api::Error);
  api::CharacterBatch batch = m.createBatch({2, 2, true});
  HostFrames host(device->device(), device->queueFamily(), 1);
  Rng rng(1);
  HostPoses poses = randomPoses(rng, model, 2);
  VkCommandBuffer cmd = host.begin(0);
  auto codeOf = [&](auto&& f) {
    try {
      f();
    } catch (const api::Error& e) {
      return e.code();
    }
    return api::ErrorCode::Internal;
  };
  EXPECT_EQ(codeOf([&] { batch.recordFrame(cmd, 0, std::span(poses.poses).first(1)); }),
            api::ErrorCode::InvalidArgument);
  auto shortPose = poses.poses;
  shortPose[1].localRotations = shortPose[1].localRotations.first(1);
  EXPECT_EQ(codeOf([&] { batch.recordFrame(cmd, 0, shortPose); }), api::ErrorCode::InvalidArgument);
  // A NaN quaternion is not an error: the rest rotation, and a warning naming the joint.
  std::vector<api::Quat> nanRot = poses.rotations[0];
  nanRot[1] = {NAN, 0, 0, 1};
  auto nanPoses = poses.poses;
  nanPoses[0].localRotations = nanRot;
  const api::FrameReport r = batch.recordFrame(cmd, 0, nanPoses);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find(model.skeleton.joints[1].name), std::string::npos) << r.warnings[0];
  // Frames in order only.
  EXPECT_EQ(codeOf([&] { batch.recordFrame(cmd, 5, poses.poses); }), api::ErrorCode::InvalidArgument);
  host.submit(device->queue(), 0);
  host.waitAll();
  // Readback before retiring is refused.
  EXPECT_EQ(codeOf([&] { batch.readBackMesh(0, 0); }), api::ErrorCode::FrameInFlight);
  batch.retireFrame(0);
  EXPECT_EQ(codeOf([&] { batch.readBackMesh(0, 2); }), api::ErrorCode::InvalidArgument);
  EXPECT_TRUE(std::isfinite(batch.readBackMesh(0, 0).positions[0]));
  test::expectNoValidationMessages(*device);
}

}  // namespace
}  // namespace swish
