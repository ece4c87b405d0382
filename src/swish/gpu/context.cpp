#include "swish/gpu/context.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "swish/gpu/vk_check.hpp"
#include "swish/gpu/vk_helpers.hpp"

namespace swish::gpu {

namespace {

constexpr const char* kValidationLayer = kValidationLayerName;

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  if (!v) return false;
  std::string s(v);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s == "1" || s == "true" || s == "on" || s == "yes";
}

std::string versionString(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

// Why a device cannot run swish, or "" when it can.
std::string unusableReason(VkPhysicalDevice pd) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(pd, &props);
  if (props.apiVersion < VK_API_VERSION_1_3)
    return "supports Vulkan " + versionString(props.apiVersion) + ", swish needs 1.3 (update the driver)";
  if (!queueFamilyWith(pd, VK_QUEUE_COMPUTE_BIT)) return "has no compute queue";
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
  VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  vkGetPhysicalDeviceFeatures2(pd, &f);
  if (!f12.bufferDeviceAddress) return "lacks the bufferDeviceAddress feature";
  if (!f13.maintenance4) return "lacks the maintenance4 feature";
  return "";
}

bool normalMapFormatUsable(VkPhysicalDevice pd) {
  VkPhysicalDeviceFeatures f;
  vkGetPhysicalDeviceFeatures(pd, &f);
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(pd, VK_FORMAT_R16G16_SNORM, &fp);
  return f.shaderStorageImageExtendedFormats && (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT);
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

}  // namespace

struct Context::Impl {
  bool ownsDevice = true;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memProps{};
  bool normalMaps = false;
  bool timestamps = false;
  bool shaderInt64 = false;
  bool validation = false;
  VkCommandPool oneTimePool = VK_NULL_HANDLE;

  mutable std::mutex messagesMutex;
  std::vector<std::string> messages;

  void record(std::string m) {
    std::lock_guard lock(messagesMutex);
    messages.push_back(std::move(m));
  }

  ~Impl() {
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      if (oneTimePool) vkDestroyCommandPool(device, oneTimePool, nullptr);
      if (ownsDevice) vkDestroyDevice(device, nullptr);
    }
    if (ownsDevice && instance != VK_NULL_HANDLE) {
      if (messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance, messenger, nullptr);
      }
      vkDestroyInstance(instance, nullptr);
    }
  }

  void finishSetup() {
    vkGetPhysicalDeviceProperties(physicalDevice, &props);
    vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memProps);
    normalMaps = normalMapFormatUsable(physicalDevice);
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
    std::vector<VkQueueFamilyProperties> fams(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, fams.data());
    timestamps = queueFamily < n && fams[queueFamily].timestampValidBits > 0 && props.limits.timestampPeriod > 0;
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT | VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pci.queueFamilyIndex = queueFamily;
    SWISH_VK(vkCreateCommandPool(device, &pci, nullptr, &oneTimePool));
  }
};

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  static_cast<Context::Impl*>(user)->record(std::string("[") + level + "] " +
                                            (data && data->pMessage ? data->pMessage : ""));
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(Context::Impl* impl) {
  return debugMessengerInfo(onDebugMessage, impl);
}

// A bare instance for listing devices, or the context's own instance when `impl` is given.
VkInstance createInstance(const ContextOptions& options, bool validation, Context::Impl* impl) {
  uint32_t loaderVersion = 0;
  if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS || loaderVersion < VK_API_VERSION_1_3)
    throw Error("the Vulkan loader supports Vulkan " + versionString(loaderVersion) +
                ", swish needs 1.3: install a newer Vulkan loader (Debian: libvulkan1)");
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = options.applicationName.c_str();
  app.pEngineName = "swish";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  const char* layer = kValidationLayer;
  const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkDebugUtilsMessengerCreateInfoEXT mi{};
  if (validation) {
    if (!instanceLayerAvailable(kValidationLayer))
      throw Error(std::string("validation was requested (SWISH_VALIDATION or an option) but ") + kValidationLayer +
                  " is not installed: install the Vulkan validation layers (Debian: vulkan-validationlayers) or turn "
                  "validation off");
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &ext;
    if (impl) {
      mi = messengerInfo(impl);  // also catches messages of vkCreateInstance/vkDestroyInstance
      ici.pNext = &mi;
    }
  }
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ici, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw Error(
        "no Vulkan driver is installed (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER): install one, e.g. "
        "Debian's mesa-vulkan-drivers for the lavapipe CPU implementation");
  if (r != VK_SUCCESS) throwVkError(r, "vkCreateInstance", __FILE__, __LINE__);
  return instance;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t n = 0;
  SWISH_VK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> pds(n);
  SWISH_VK(vkEnumeratePhysicalDevices(instance, &n, pds.data()));
  pds.resize(n);
  return pds;
}

std::vector<PhysicalDeviceInfo> describe(const std::vector<VkPhysicalDevice>& pds) {
  std::vector<PhysicalDeviceInfo> out;
  for (uint32_t i = 0; i < pds.size(); ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(pds[i], &p);
    PhysicalDeviceInfo d;
    d.index = i;
    d.name = p.deviceName;
    d.type = p.deviceType;
    d.apiVersion = p.apiVersion;
    d.unusableReason = unusableReason(pds[i]);
    d.usable = d.unusableReason.empty();
    out.push_back(std::move(d));
  }
  return out;
}

std::string deviceList(const std::vector<PhysicalDeviceInfo>& devs) {
  std::string s;
  for (const auto& d : devs)
    s += "\n  " + std::to_string(d.index) + ": " + d.name + " (" + deviceTypeName(d.type) + ")" +
         (d.usable ? "" : " - unusable: " + d.unusableReason);
  return s;
}

// Index into devs of the device to use, or throws Error saying why none can be.
int pick(const std::vector<PhysicalDeviceInfo>& devs, const std::string& request) {
  if (devs.empty())
    throw Error(
        "no Vulkan device found: install a Vulkan driver (for a CPU fallback, Debian's mesa-vulkan-drivers provides "
        "lavapipe)");
  if (!request.empty()) {
    int found = -1;
    for (const auto& d : devs)
      if (deviceMatches(request, d.index, d.name)) {
        found = int(d.index);
        break;
      }
    if (found < 0)
      throw Error("no Vulkan device matches '" + request +
                  "' (SWISH_DEVICE or --device: an index or a name substring); devices:" + deviceList(devs));
    if (!devs[found].usable)
      throw Error("Vulkan device '" + devs[found].name + "' cannot run swish: " + devs[found].unusableReason);
    return found;
  }
  int best = -1;
  for (const auto& d : devs)
    if (d.usable && (best < 0 || deviceTypeRank(d.type) < deviceTypeRank(devs[best].type))) best = int(d.index);
  if (best < 0) throw Error("no Vulkan device can run swish; devices:" + deviceList(devs));
  return best;
}

}  // namespace

const char* deviceTypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

std::vector<PhysicalDeviceInfo> Context::listDevices(const ContextOptions& options, int& picked, std::string& whyNone) {
  VkInstance instance = createInstance(options, false, nullptr);
  std::vector<PhysicalDeviceInfo> devs;
  try {
    devs = describe(physicalDevices(instance));
    picked = -1;
    try {
      picked = pick(devs, requestedDevice(options.device));
    } catch (const Error& e) {
      whyNone = e.what();
    }
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return devs;
}

Context Context::create(const ContextOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->validation = options.validation ? *options.validation : envFlag("SWISH_VALIDATION");
  impl->instance = createInstance(options, impl->validation, impl.get());
  if (impl->validation) {
    auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(impl->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!createMessenger) throw Error("VK_EXT_debug_utils is not available although the validation layer is");
    const auto mi = messengerInfo(impl.get());
    SWISH_VK(createMessenger(impl->instance, &mi, nullptr, &impl->messenger));
  }
  const auto pds = physicalDevices(impl->instance);
  const int chosen = pick(describe(pds), requestedDevice(options.device));
  impl->physicalDevice = pds[chosen];
  impl->queueFamily = *queueFamilyWith(impl->physicalDevice, VK_QUEUE_COMPUTE_BIT);

  VkPhysicalDeviceFeatures supported;
  vkGetPhysicalDeviceFeatures(impl->physicalDevice, &supported);
  // maintenance4: the shaders size workgroups with specialisation constants (SPIR-V LocalSizeId).
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.maintenance4 = VK_TRUE;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
  f12.bufferDeviceAddress = VK_TRUE;
  VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  f.features.shaderStorageImageExtendedFormats = supported.shaderStorageImageExtendedFormats;
  // Optional: the normal-map blend stores through 64-bit words where it can (normal_map_blend_pass.hpp).
  f.features.shaderInt64 = supported.shaderInt64;
  const float priority = 1.f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = impl->queueFamily;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  const VkResult r = vkCreateDevice(impl->physicalDevice, &dci, nullptr, &impl->device);
  if (r == VK_ERROR_FEATURE_NOT_PRESENT || r == VK_ERROR_EXTENSION_NOT_PRESENT)
    throw Error(std::string("the Vulkan device refused the features swish needs (") + vkResultName(r) + ")");
  if (r != VK_SUCCESS) throwVkError(r, "vkCreateDevice", __FILE__, __LINE__);
  impl->shaderInt64 = supported.shaderInt64 == VK_TRUE;
  vkGetDeviceQueue(impl->device, impl->queueFamily, 0, &impl->queue);
  impl->finishSetup();
  return Context(std::move(impl));
}

Expected<Context> Context::tryCreate(const ContextOptions& options) {
  try {
    return create(options);
  } catch (const Error& e) {
    return e;
  }
}

Context Context::adopt(const AdoptedDevice& host) {
  if (!host.instance || !host.physicalDevice || !host.device || !host.queue)
    throw Error("adopting a host device: instance, physical device, device and queue must all be given");
  const std::string why = unusableReason(host.physicalDevice);
  if (!why.empty()) throw Error("adopting a host device: the device " + why);
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(host.physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(host.physicalDevice, &n, fams.data());
  if (host.queueFamily >= n || !(fams[host.queueFamily].queueFlags & VK_QUEUE_COMPUTE_BIT))
    throw Error("adopting a host device: queue family " + std::to_string(host.queueFamily) +
                " does not support compute");
  auto impl = std::make_unique<Impl>();
  impl->ownsDevice = false;
  impl->instance = host.instance;
  impl->physicalDevice = host.physicalDevice;
  impl->device = host.device;
  impl->queue = host.queue;
  impl->queueFamily = host.queueFamily;
  impl->finishSetup();
  return Context(std::move(impl));
}

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

VkInstance Context::instance() const { return impl_->instance; }
VkPhysicalDevice Context::physicalDevice() const { return impl_->physicalDevice; }
VkDevice Context::device() const { return impl_->device; }
VkQueue Context::queue() const { return impl_->queue; }
uint32_t Context::queueFamily() const { return impl_->queueFamily; }
const VkPhysicalDeviceProperties& Context::properties() const { return impl_->props; }
std::string Context::deviceName() const { return impl_->props.deviceName; }
bool Context::ownsDevice() const { return impl_->ownsDevice; }
bool Context::supportsNormalMaps() const { return impl_->normalMaps; }
bool Context::hasShaderInt64() const { return impl_->shaderInt64; }
bool Context::supportsTimestamps() const { return impl_->timestamps; }
double Context::timestampPeriodNs() const { return impl_->props.limits.timestampPeriod; }
bool Context::validationEnabled() const { return impl_->validation; }

size_t Context::validationMessageCount() const {
  std::lock_guard lock(impl_->messagesMutex);
  return impl_->messages.size();
}
std::vector<std::string> Context::validationMessages() const {
  std::lock_guard lock(impl_->messagesMutex);
  return impl_->messages;
}
void Context::clearValidationMessages() {
  std::lock_guard lock(impl_->messagesMutex);
  impl_->messages.clear();
}

uint32_t Context::memoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
  if (const auto t = findMemoryType(impl_->memProps, typeBits, required, preferred)) return *t;
  throw Error("the Vulkan device '" + deviceName() + "' has no memory type with the properties swish needs");
}

VkCommandBuffer Context::beginOneTime() {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = impl_->oneTimePool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  SWISH_VK(vkAllocateCommandBuffers(impl_->device, &ai, &cmd));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  SWISH_VK(vkBeginCommandBuffer(cmd, &bi));
  return cmd;
}

void Context::abandonOneTime(VkCommandBuffer cmd) { vkFreeCommandBuffers(impl_->device, impl_->oneTimePool, 1, &cmd); }

void Context::endOneTimeAndWait(VkCommandBuffer cmd) {
  struct FreeOnExit {
    Context* c;
    VkCommandBuffer cmd;
    ~FreeOnExit() { c->abandonOneTime(cmd); }
  } freeOnExit{this, cmd};
  SWISH_VK(vkEndCommandBuffer(cmd));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  SWISH_VK(vkCreateFence(impl_->device, &fci, nullptr, &fence));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  VkResult r = vkQueueSubmit(impl_->queue, 1, &si, fence);
  if (r == VK_SUCCESS) r = vkWaitForFences(impl_->device, 1, &fence, VK_TRUE, UINT64_MAX);
  vkDestroyFence(impl_->device, fence, nullptr);
  if (r != VK_SUCCESS) throwVkError(r, "vkQueueSubmit/vkWaitForFences", __FILE__, __LINE__);
}

}  // namespace swish::gpu
