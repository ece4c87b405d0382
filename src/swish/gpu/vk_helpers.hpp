#pragma once
// Small Vulkan queries that two owners of a device need: the library's own context (gpu/context.cpp)
// and the preview renderer's host device (render/host_device.cpp), which is built like any host on the
// public API and so makes its own instance and device. Written once here; C API only, and nothing else
// of the gpu layer comes with this header (as with vk_unique.hpp, the preview's other borrowing).
// Errors stay with the callers: these return what they found, and each owner says it its own way.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <string>

namespace swish::gpu {

inline constexpr const char* kValidationLayerName = "VK_LAYER_KHRONOS_validation";

// Whether the loader lists the instance layer `name`.
bool instanceLayerAvailable(const char* name);

// The first queue family of `physicalDevice` whose flags hold all of `flags`.
std::optional<uint32_t> queueFamilyWith(VkPhysicalDevice physicalDevice, VkQueueFlags flags);

// The first memory type allowed by `typeBits` with all of required | preferred, else the first with all
// of `required`; nullopt when there is none.
std::optional<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t typeBits,
                                       VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0);

// Automatic device choice: discrete GPUs first, then integrated, virtual, CPU implementations (lavapipe),
// other types last. Lower is better; ties go to the lower device index.
int deviceTypeRank(VkPhysicalDeviceType type);

// The device a user asked for: `option` (a --device flag, an options field) when set, else the
// environment variable SWISH_DEVICE, else "" (choose automatically).
std::string requestedDevice(const std::string& option);
// Whether device `index`, named `name`, is the one `request` names: an index ("1") or a case-insensitive
// substring of the name ("nvidia", "llvmpipe"). An empty request matches every device.
bool deviceMatches(const std::string& request, uint32_t index, const std::string& name);

// What a debug-utils messenger should hear: warnings and errors of every message type, delivered to
// `callback` with `user`.
VkDebugUtilsMessengerCreateInfoEXT debugMessengerInfo(PFN_vkDebugUtilsMessengerCallbackEXT callback, void* user);

}  // namespace swish::gpu
