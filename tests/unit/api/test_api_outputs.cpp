// The public API's plain parts, no device needed: the consumer barriers FrameOutputs builds (same
// family: a memory dependency; another family: an ownership transfer; no maps: no image barrier),
// Result<T> as a value or an error, and error-code names.
#include <gtest/gtest.h>

#include "swish/swish.hpp"

namespace swish {
namespace {

api::FrameOutputs sampleOutputs(bool maps) {
  api::FrameOutputs o;
  o.queueFamily = 2;
  o.positions.buffer = reinterpret_cast<VkBuffer>(uintptr_t(0x10));
  o.normals.buffer = reinterpret_cast<VkBuffer>(uintptr_t(0x20));
  o.tangents.buffer = reinterpret_cast<VkBuffer>(uintptr_t(0x30));
  if (maps) {
    api::NormalMapOutput m;
    m.image = reinterpret_cast<VkImage>(uintptr_t(0x40));
    m.layout = VK_IMAGE_LAYOUT_GENERAL;
    m.range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 3};
    o.normalMaps = m;
  }
  return o;
}

TEST(ApiOutputs, SameFamilyBarriersAreMemoryDependenciesFromComputeWrites) {
  const auto o = sampleOutputs(true);
  const auto b = o.vertexBarriers();
  ASSERT_EQ(b.size(), 3u);
  for (const auto& x : b) {
    EXPECT_EQ(x.srcStageMask, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    EXPECT_EQ(x.srcAccessMask, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    EXPECT_EQ(x.dstStageMask, VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT);
    EXPECT_EQ(x.dstAccessMask, VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT);
    EXPECT_EQ(x.srcQueueFamilyIndex, VK_QUEUE_FAMILY_IGNORED);
    EXPECT_EQ(x.dstQueueFamilyIndex, VK_QUEUE_FAMILY_IGNORED);
    EXPECT_EQ(x.size, VK_WHOLE_SIZE);
  }
  EXPECT_EQ(b[0].buffer, o.positions.buffer);
  EXPECT_EQ(b[2].buffer, o.tangents.buffer);
  // Naming the owner's own family is still no transfer.
  EXPECT_EQ(o.vertexBarriers(2)[0].srcQueueFamilyIndex, VK_QUEUE_FAMILY_IGNORED);
  const auto img = o.normalMapBarrier();
  ASSERT_TRUE(img.has_value());
  EXPECT_EQ(img->oldLayout, VK_IMAGE_LAYOUT_GENERAL);
  EXPECT_EQ(img->newLayout, VK_IMAGE_LAYOUT_GENERAL);  // never a transition
  EXPECT_EQ(img->dstStageMask, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
  EXPECT_EQ(img->dstAccessMask, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  EXPECT_EQ(img->subresourceRange.layerCount, 3u);
}

TEST(ApiOutputs, AnotherFamilyMakesAnOwnershipTransfer) {
  const auto o = sampleOutputs(true);
  const auto b = o.vertexBarriers(5, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  EXPECT_EQ(b[1].srcQueueFamilyIndex, 2u);
  EXPECT_EQ(b[1].dstQueueFamilyIndex, 5u);
  EXPECT_EQ(b[1].dstStageMask, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  EXPECT_EQ(b[1].dstAccessMask, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  EXPECT_EQ(o.normalMapBarrier(5)->dstQueueFamilyIndex, 5u);
}

TEST(ApiOutputs, NoNormalMapsNoImageBarrier) {
  EXPECT_FALSE(sampleOutputs(false).normalMapBarrier().has_value());
  auto o = sampleOutputs(false);
  o.tangents.buffer = VK_NULL_HANDLE;  // a stream that is absent gets no barrier
  EXPECT_EQ(o.vertexBarriers().size(), 2u);
}

TEST(ApiOutputs, ResultHoldsAValueOrAnError) {
  api::Result<int> good = 7;
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good.value(), 7);
  api::Result<int> bad = api::Error(api::ErrorCode::BadModel, "m.swish: section 'MESH': truncated");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code(), api::ErrorCode::BadModel);
  try {
    bad.value();
    FAIL() << "value() of an error must throw it";
  } catch (const api::Error& e) {
    EXPECT_EQ(e.code(), api::ErrorCode::BadModel);
    EXPECT_STREQ(e.what(), "m.swish: section 'MESH': truncated");
  }
  EXPECT_STREQ(api::errorCodeName(api::ErrorCode::FrameInFlight), "frame in flight");
}

}  // namespace
}  // namespace swish
