#pragma once
// The Vulkan context swish runs on: instance, physical device, device and one compute-capable queue.
// Either made by swish (headless, Vulkan 1.3) or ADOPTED from a host renderer (whose handles swish
// uses but never destroys).
//
// Device choice when swish makes it: discrete GPU first, then integrated, virtual, then CPU
// implementations (lavapipe) last; ContextOptions::device or the environment variable SWISH_DEVICE
// overrides it with a device index (as `swish devices` lists them) or a case-insensitive substring
// of the device name.
//
// Required of the device (swish enables them on its own device; a host must have enabled them on an
// adopted one): Vulkan 1.3, a compute queue, bufferDeviceAddress (buffers are passed to kernels as
// addresses in push constants), maintenance4 (workgroup sizes are specialisation constants). For normal maps also
// shaderStorageImageExtendedFormats and storage image support of VK_FORMAT_R16G16_SNORM. Missing ones give a
// swish::Error saying which.
//
// Validation: ContextOptions::validation, or SWISH_VALIDATION=1, enables VK_LAYER_KHRONOS_validation
// with a debug messenger recording every warning and error message; tests assert there are none.
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swish/core/error.hpp"

namespace swish::gpu {

struct ContextOptions {
  std::string device;              // index or name substring; empty: SWISH_DEVICE, else automatic
  std::optional<bool> validation;  // unset: SWISH_VALIDATION (1/true/on enables)
  std::string applicationName = "swish";
};

// What a host renderer hands over. swish does not take ownership; the host keeps every handle alive
// for the lifetime of the Context and synchronises its own use of `queue` with swish's uploads.
struct AdoptedDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
};

struct PhysicalDeviceInfo {
  uint32_t index = 0;  // in vkEnumeratePhysicalDevices order
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t apiVersion = 0;
  bool usable = false;         // meets the requirements above
  std::string unusableReason;  // why not, when !usable
};

const char* deviceTypeName(VkPhysicalDeviceType t);

class Context {
 public:
  // Throws swish::Error with an actionable reason (no loader, no Vulkan 1.3, no device, no match for
  // the requested device, missing feature, validation layer asked for but not installed).
  static Context create(const ContextOptions& options = {});
  static Expected<Context> tryCreate(const ContextOptions& options = {});
  static Context adopt(const AdoptedDevice& host);

  // Lists every physical device, with usability, and which one create() would pick (index into the
  // returned list, or -1 with the reason in `whyNone`).
  static std::vector<PhysicalDeviceInfo> listDevices(const ContextOptions& options, int& picked, std::string& whyNone);

  Context(Context&&) noexcept;
  Context& operator=(Context&&) noexcept;
  ~Context();

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const;
  VkDevice device() const;
  VkQueue queue() const;
  uint32_t queueFamily() const;
  const VkPhysicalDeviceProperties& properties() const;
  std::string deviceName() const;
  bool ownsDevice() const;
  bool supportsNormalMaps() const;  // storage images of R16G16_SNORM usable
  bool supportsTimestamps() const;
  // 64-bit integers in shaders (shaderInt64): enabled on swish's own device when supported; never
  // assumed on an adopted device (a host need not have enabled it, and Vulkan cannot be asked).
  bool hasShaderInt64() const;
  double timestampPeriodNs() const;

  // Index of a memory type allowed by `typeBits` having `required` flags, preferring `preferred` too;
  // throws Error when none.
  uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0) const;

  // Validation messages (warnings and errors) recorded since creation or the last clear.
  bool validationEnabled() const;
  size_t validationMessageCount() const;
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages();

  // Records with `record` into a one-time command buffer, submits it on the queue and waits. For
  // uploads, tests and tools; frame work is recorded into the caller's own command buffers.
  template <class F>
  void submitAndWait(F&& record) {
    VkCommandBuffer cmd = beginOneTime();
    try {
      record(cmd);
    } catch (...) {
      abandonOneTime(cmd);
      throw;
    }
    endOneTimeAndWait(cmd);
  }
  VkCommandBuffer beginOneTime();
  void endOneTimeAndWait(VkCommandBuffer cmd);
  void abandonOneTime(VkCommandBuffer cmd);

  struct Impl;

 private:
  explicit Context(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swish::gpu
