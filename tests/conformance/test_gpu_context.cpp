// The Vulkan context: device choice and its override, errors a person can act on, validation
// messages recorded, and adoption of a host renderer's device (swish runs on handles it does not own).
#include <cstdio>

#include "support/gpu_test.hpp"
#include "support/random_model.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"

namespace swish {
namespace {

class GpuContext : public test::GpuTest {};

TEST_F(GpuContext, ListsTheChosenDeviceAndPrefersRealGpus) {
  int picked = -1;
  std::string why;
  const auto devices = gpu::Context::listDevices(test::gpuTestOptions(), picked, why);
  ASSERT_GE(picked, 0) << why;
  EXPECT_EQ(devices[size_t(picked)].name, ctx().deviceName());
  std::printf("picked %s of %zu device(s)\n", devices[size_t(picked)].name.c_str(), devices.size());
  if (!std::getenv("SWISH_DEVICE")) {
    for (const auto& d : devices) {  // nothing usable ranks above the pick
      if (d.usable && d.type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) {
        EXPECT_EQ(devices[size_t(picked)].type, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU);
      }
    }
  }
}

TEST_F(GpuContext, SelectingByIndexAndByNameFindsTheSameDevice) {
  int picked = -1;
  std::string why;
  const auto devices = gpu::Context::listDevices(test::gpuTestOptions(), picked, why);
  ASSERT_GE(picked, 0) << why;
  auto byIndex = test::gpuTestOptions();
  byIndex.device = std::to_string(picked);
  auto byName = test::gpuTestOptions();
  byName.device = devices[size_t(picked)].name.substr(0, 6);
  EXPECT_EQ(gpu::Context::create(byIndex).deviceName(), ctx().deviceName());
  EXPECT_NE(gpu::Context::create(byName).deviceName().find(byName.device), std::string::npos);
}

TEST_F(GpuContext, UnknownDeviceIsAnErrorListingTheDevices) {
  auto o = test::gpuTestOptions();
  o.device = "no-such-gpu-xyz";
  auto made = gpu::Context::tryCreate(o);
  ASSERT_FALSE(made.ok());
  const std::string what = made.error().what();
  EXPECT_NE(what.find("no-such-gpu-xyz"), std::string::npos) << what;
  EXPECT_NE(what.find(ctx().deviceName()), std::string::npos) << "the message should list the devices: " << what;
  o.device = "999";
  EXPECT_FALSE(gpu::Context::tryCreate(o).ok());
}

TEST_F(GpuContext, ValidationMessagesAreRecorded) {
  if (!ctx().validationEnabled()) GTEST_SKIP() << "validation is off (SWISH_VALIDATION=0)";
  // A deliberate misuse: a buffer of size 0 is invalid usage, which the layer must report.
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = 0;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer b = VK_NULL_HANDLE;
  vkCreateBuffer(ctx().device(), &bci, nullptr, &b);
  if (b) vkDestroyBuffer(ctx().device(), b, nullptr);
  EXPECT_GT(ctx().validationMessageCount(), 0u);
  ctx().clearValidationMessages();  // expected ones: the fixture must not fail on them
}

// A host renderer's device: swish adopts the handles, runs a frame on them and leaves them alive.
TEST_F(GpuContext, AdoptedHostDeviceRunsAFrameAndStaysOwnedByTheHost) {
  gpu::AdoptedDevice host{ctx().instance(), ctx().physicalDevice(), ctx().device(), ctx().queue(), ctx().queueFamily()};
  Rng rng(test::testSeed(0xAD0));
  test::RandomModelSpec spec;
  spec.vertices = 30;
  const Model model = test::makeRandomModel(rng, spec);
  {
    gpu::Context adopted = gpu::Context::adopt(host);
    EXPECT_FALSE(adopted.ownsDevice());
    gpu::GpuModel gm(adopted, model);
    gpu::FrameRecorder rec(adopted, gm, 2, {2, true, true});
    runtime::FrameKernelInputs in;
    in.instanceCount = 2;
    in.meshWeights.assign(2 * size_t(model.meshComponents()), 0.f);
    for (int i = 0; i < 2; ++i) {
      const auto m = model.skeleton.skinningMatrices(model.skeleton.restPose());
      in.skinMatrices.insert(in.skinMatrices.end(), m.begin(), m.end());
    }
    adopted.submitAndWait([&](VkCommandBuffer cmd) { rec.record(cmd, 0, in); });
    const auto out = rec.download(0);
    ASSERT_EQ(out.positions.size(), 2u);
    // Zero PCA weights at the rest pose give the rest mesh back.
    EXPECT_TRUE(out.positions[1].isApprox(model.gameMesh.positions, 1e-5f));
  }
  // The host's device still works after the adopted context is gone.
  EXPECT_EQ(vkDeviceWaitIdle(ctx().device()), VK_SUCCESS);
  EXPECT_THROW(gpu::Context::adopt({}), Error);
}

}  // namespace
}  // namespace swish
