#include "swish/render/host_device.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

#include "swish/api_error.hpp"
#include "swish/api_runtime.hpp"
#include "swish/gpu/vk_helpers.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace swish::render {

namespace {

[[noreturn]] void fail(const std::string& why) {
  throw api::Error(api::ErrorCode::DeviceUnsupported, "host device: " + why);
}

void check(VkResult r, const char* call) {
  if (r != VK_SUCCESS)
    throw api::Error(api::ErrorCode::VulkanFailure,
                     std::string("host device: ") + call + " returned " + std::to_string(int(r)));
}

}  // namespace

VKAPI_ATTR VkBool32 VKAPI_CALL HostDevice::onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<HostDevice*>(user);
  std::lock_guard lock(self->mutex_);
  self->messages_.push_back(data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;
}

HostDevice::HostDevice(const HostDeviceOptions& options) {
  const char* kLayer = gpu::kValidationLayerName;
  if (options.validation && !gpu::instanceLayerAvailable(kLayer))
    fail("validation asked for, but VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)");
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "swish preview";
  app.apiVersion = VK_API_VERSION_1_3;
  const VkDebugUtilsMessengerCreateInfoEXT mi = gpu::debugMessengerInfo(&HostDevice::onMessage, this);
  const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (options.validation) {
    ici.pNext = &mi;  // also catches messages of vkCreateInstance/vkDestroyInstance themselves
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &kLayer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &ext;
  }
  const VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER) fail("no Vulkan driver (install mesa-vulkan-drivers for lavapipe)");
  check(r, "vkCreateInstance");
  try {
    if (options.validation) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) fail("VK_EXT_debug_utils is missing");
      check(create(instance_, &mi, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance_, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(instance_, &n, pds.data());
    const std::string want = gpu::requestedDevice(options.device);
    std::string reasons;
    int best = -1, bestRank = 0;
    for (uint32_t i = 0; i < n; ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(pds[i], &p);
      if (!gpu::deviceMatches(want, i, p.deviceName)) continue;
      std::string why = api::unsuitableReason(pds[i]);
      if (why.empty() && !gpu::queueFamilyWith(pds[i], VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
        why = std::string(p.deviceName) + " has no graphics+compute queue";
      if (!why.empty()) {
        reasons += "; " + why;
        continue;
      }
      if (best < 0 || gpu::deviceTypeRank(p.deviceType) < bestRank)
        best = int(i), bestRank = gpu::deviceTypeRank(p.deviceType);
    }
    if (best < 0)
      fail("no usable Vulkan device" + (want.empty() ? std::string() : " matching '" + want + "'") + reasons);
    physical_ = pds[best];
    family_ = *gpu::queueFamilyWith(physical_, VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT);

    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.synchronization2 = VK_TRUE;  // the renderer's own barriers use vkCmdPipelineBarrier2
    f13.dynamicRendering = VK_TRUE;  // the preview draws without render pass objects
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
    api::enableRequiredFeatures(physical_, f, f12, f13);
    const float priority = 1.f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, family_, 0, &queue_);
  } catch (...) {
    release();
    throw;
  }
}

HostDevice::~HostDevice() { release(); }

void HostDevice::release() {
  if (device_) vkDestroyDevice(device_, nullptr);
  device_ = VK_NULL_HANDLE;
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  instance_ = VK_NULL_HANDLE;
}

api::DeviceHandles HostDevice::handles() const { return {instance_, physical_, device_, queue_, family_}; }

std::string HostDevice::deviceName() const {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(physical_, &p);
  return p.deviceName;
}

std::vector<std::string> HostDevice::validationMessages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

void HostDevice::clearValidationMessages() {
  std::lock_guard lock(mutex_);
  messages_.clear();
}

uint32_t HostDevice::memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  if (const auto t = gpu::findMemoryType(mp, typeBits, flags)) return *t;
  throw api::Error(api::ErrorCode::DeviceUnsupported,
                   "host device: no memory type with the properties the preview needs");
}

}  // namespace swish::render
