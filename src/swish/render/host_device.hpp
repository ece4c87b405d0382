#pragma once
// A Vulkan device made the way a host renderer makes one, for the preview renderer and the API tests:
// instance (optionally with the validation layer and a messenger that collects every warning and
// error), a physical device that can run swish (api::unsuitableReason) and has a graphics+compute
// queue family, and a device with swish's required features (api::enableRequiredFeatures). It is then
// handed to swish with api::Runtime::adopt(handles()).
//
// Device choice: `device` (index in vkEnumeratePhysicalDevices order, or case-insensitive name
// substring), else SWISH_DEVICE, else the first discrete GPU, then any usable device.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "swish/api_types.hpp"

namespace swish::render {

struct HostDeviceOptions {
  bool validation = false;
  std::string device;
};

class HostDevice {
 public:
  // Throws swish::api::Error (DeviceUnsupported) with the reason when no device fits.
  explicit HostDevice(const HostDeviceOptions& options = {});
  ~HostDevice();
  HostDevice(const HostDevice&) = delete;
  HostDevice& operator=(const HostDevice&) = delete;

  api::DeviceHandles handles() const;
  VkDevice device() const { return device_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return family_; }
  std::string deviceName() const;

  // Validation messages (warnings and errors) since creation or the last clear.
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages();

  // Index of a memory type allowed by typeBits with `flags`; throws when none.
  uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;

 private:
  void release();
  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                  const VkDebugUtilsMessengerCallbackDataEXT*, void*);
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

}  // namespace swish::render
