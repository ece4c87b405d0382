#include "swish/gpu/vk_helpers.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace swish::gpu {

bool instanceLayerAvailable(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (uint32_t i = 0; i < n && i < layers.size(); ++i)
    if (std::strcmp(layers[i].layerName, name) == 0) return true;
  return false;
}

std::optional<uint32_t> queueFamilyWith(VkPhysicalDevice pd, VkQueueFlags flags) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, fams.data());
  for (uint32_t i = 0; i < n; ++i)
    if ((fams[i].queueFlags & flags) == flags) return i;
  return std::nullopt;
}

std::optional<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& mp, uint32_t typeBits,
                                       VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
  for (int pass = 0; pass < 2; ++pass) {
    const VkMemoryPropertyFlags want = pass == 0 ? (required | preferred) : required;
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
      if ((typeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
  }
  return std::nullopt;
}

int deviceTypeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

std::string requestedDevice(const std::string& option) {
  if (!option.empty()) return option;
  if (const char* e = std::getenv("SWISH_DEVICE")) return e;
  return "";
}

bool deviceMatches(const std::string& request, uint32_t index, const std::string& name) {
  if (request.empty()) return true;
  if (std::all_of(request.begin(), request.end(), [](unsigned char c) { return std::isdigit(c); }))
    return std::strtoul(request.c_str(), nullptr, 10) == index;
  auto lower = [](std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
  };
  return lower(name).find(lower(request)) != std::string::npos;
}

VkDebugUtilsMessengerCreateInfoEXT debugMessengerInfo(PFN_vkDebugUtilsMessengerCallbackEXT callback, void* user) {
  VkDebugUtilsMessengerCreateInfoEXT mi{};
  mi.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = callback;
  mi.pUserData = user;
  return mi;
}

}  // namespace swish::gpu
