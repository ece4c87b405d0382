// The Vulkan helpers that the library's context and the preview's host device share
// (gpu/vk_helpers.hpp): the parts that need no device.
#include <gtest/gtest.h>

#include <cstdlib>

#include "swish/gpu/vk_helpers.hpp"

namespace {

using namespace swish::gpu;

TEST(VkHelpers, DeviceRequestIsAnIndexOrANameSubstring) {
  EXPECT_TRUE(deviceMatches("", 3, "anything"));
  EXPECT_TRUE(deviceMatches("1", 1, "NVIDIA H100"));
  EXPECT_TRUE(deviceMatches("01", 1, "NVIDIA H100"));     // an index, read as a number
  EXPECT_FALSE(deviceMatches("1", 0, "device 1 alpha"));  // digits are an index, never a name
  EXPECT_TRUE(deviceMatches("nvidia", 0, "NVIDIA H100"));
  EXPECT_TRUE(deviceMatches("LLVMpipe", 2, "llvmpipe (LLVM 15.0.6, 256 bits)"));
  EXPECT_FALSE(deviceMatches("amd", 0, "NVIDIA H100"));
}

TEST(VkHelpers, RequestedDeviceTakesTheOptionBeforeTheEnvironment) {
  const char* saved = std::getenv("SWISH_DEVICE");
  const std::string restore = saved ? saved : "";
  setenv("SWISH_DEVICE", "llvm", 1);
  EXPECT_EQ(requestedDevice("nvidia"), "nvidia");
  EXPECT_EQ(requestedDevice(""), "llvm");
  unsetenv("SWISH_DEVICE");
  EXPECT_EQ(requestedDevice(""), "");
  if (saved) setenv("SWISH_DEVICE", restore.c_str(), 1);
}

TEST(VkHelpers, DevicesRankDiscreteFirstAndCpuImplementationsLate) {
  EXPECT_LT(deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
            deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU));
  EXPECT_LT(deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
            deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU));
  EXPECT_LT(deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU), deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_CPU));
  EXPECT_LT(deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_CPU), deviceTypeRank(VK_PHYSICAL_DEVICE_TYPE_OTHER));
}

TEST(VkHelpers, MemoryTypePrefersThenRequires) {
  VkPhysicalDeviceMemoryProperties mp{};
  mp.memoryTypeCount = 3;
  mp.memoryTypes[0].propertyFlags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  mp.memoryTypes[1].propertyFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  mp.memoryTypes[2].propertyFlags =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  EXPECT_EQ(findMemoryType(mp, 0b111, host), 1u);                                      // the first that has it
  EXPECT_EQ(findMemoryType(mp, 0b111, host, VK_MEMORY_PROPERTY_HOST_CACHED_BIT), 2u);  // preferred when there
  EXPECT_EQ(findMemoryType(mp, 0b011, host, VK_MEMORY_PROPERTY_HOST_CACHED_BIT), 1u);  // else required alone
  EXPECT_EQ(findMemoryType(mp, 0b001, host), std::nullopt);                            // type bits rule
  EXPECT_EQ(findMemoryType(mp, 0b111, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT), 0u);
}

}  // namespace
