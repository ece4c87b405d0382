#include "swish/render/host_device.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

#include "swish/api_error.hpp"
#include "swish/api_runtime.hpp"

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

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

int graphicsComputeFamily(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, fams.data());
  const VkQueueFlags want = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  for (uint32_t i = 0; i < n; ++i)
    if ((fams[i].queueFlags & want) == want) return int(i);
  return -1;
}

bool layerAvailable(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
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
  const char* kLayer = "VK_LAYER_KHRONOS_validation";
  if (options.validation && !layerAvailable(kLayer))
    fail("validation asked for, but VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)");
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "swish preview";
  app.apiVersion = VK_API_VERSION_1_3;
  VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = &HostDevice::onMessage;
  mi.pUserData = this;
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
    std::string want = options.device;
    if (want.empty())
      if (const char* env = std::getenv("SWISH_DEVICE")) want = env;
    std::string reasons;
    int best = -1, bestScore = -1;
    for (uint32_t i = 0; i < n; ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(pds[i], &p);
      if (!want.empty()) {
        const bool isIndex = std::all_of(want.begin(), want.end(), [](unsigned char c) { return std::isdigit(c); });
        if (isIndex ? std::to_string(i) != want : lower(p.deviceName).find(lower(want)) == std::string::npos) continue;
      }
      std::string why = api::unsuitableReason(pds[i]);
      if (why.empty() && graphicsComputeFamily(pds[i]) < 0)
        why = std::string(p.deviceName) + " has no graphics+compute queue";
      if (!why.empty()) {
        reasons += "; " + why;
        continue;
      }
      const int score = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 3
                        : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                        : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU            ? 0
                                                                                 : 1;
      if (score > bestScore) best = int(i), bestScore = score;
    }
    if (best < 0)
      fail("no usable Vulkan device" + (want.empty() ? std::string() : " matching '" + want + "'") + reasons);
    physical_ = pds[best];
    family_ = uint32_t(graphicsComputeFamily(physical_));

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
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw api::Error(api::ErrorCode::DeviceUnsupported,
                   "host device: no memory type with the properties the preview needs");
}

}  // namespace swish::render
