// Runtime: a gpu::Context made by swish or adopted from the host, and model loading onto it.
#include <vector>

#include "swish/api/api_impl.hpp"
#include "swish/model/model_file.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"  // Vulkan structs: other members zero on purpose

namespace swish::api {

namespace {

bool hasComputeQueue(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  for (const auto& f : families)
    if (f.queueFlags & VK_QUEUE_COMPUTE_BIT) return true;
  return false;
}

Model makeModel(const std::shared_ptr<RuntimeImpl>& rt, swish::Model model, const std::string& name) {
  auto impl = std::make_shared<ModelImpl>();
  impl->runtime = rt;
  impl->model = std::move(model);
  impl->info = describeModel(impl->model, name);
  impl->gpuModel = std::make_unique<gpu::GpuModel>(rt->ctx, impl->model, name);
  return Model(std::move(impl));
}

}  // namespace

std::string unsuitableReason(VkPhysicalDevice pd) {
  if (pd == VK_NULL_HANDLE) return "no physical device given";
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(pd, &props);
  if (props.apiVersion < VK_API_VERSION_1_3) return std::string(props.deviceName) + " does not support Vulkan 1.3";
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
  VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  vkGetPhysicalDeviceFeatures2(pd, &f);
  if (!f12.bufferDeviceAddress) return std::string(props.deviceName) + " lacks the bufferDeviceAddress feature";
  if (!f13.maintenance4) return std::string(props.deviceName) + " lacks the maintenance4 feature";
  if (!hasComputeQueue(pd)) return std::string(props.deviceName) + " has no compute queue";
  return {};
}

void enableRequiredFeatures(VkPhysicalDevice pd, VkPhysicalDeviceFeatures2& features,
                            VkPhysicalDeviceVulkan12Features& v12, VkPhysicalDeviceVulkan13Features& v13) {
  v12.bufferDeviceAddress = VK_TRUE;  // kernels take buffers as addresses in push constants
  v13.maintenance4 = VK_TRUE;         // workgroup sizes are specialisation constants (LocalSizeId)
  // Storage images of R16G16_SNORM for the normal maps, where the device has them.
  VkPhysicalDeviceFeatures supported;
  vkGetPhysicalDeviceFeatures(pd, &supported);
  if (supported.shaderStorageImageExtendedFormats) features.features.shaderStorageImageExtendedFormats = VK_TRUE;
}

Runtime::Runtime(std::shared_ptr<RuntimeImpl> impl) : impl_(std::move(impl)) {}

Runtime Runtime::create(const RuntimeOptions& options) {
  return translateErrors(ErrorCode::DeviceUnsupported, [&] {
    gpu::ContextOptions o;
    o.device = options.device;
    o.validation = options.validation;
    o.applicationName = options.applicationName;
    return Runtime(std::make_shared<RuntimeImpl>(gpu::Context::create(o)));
  });
}

Result<Runtime> Runtime::tryCreate(const RuntimeOptions& options) noexcept {
  try {
    return create(options);
  } catch (const Error& e) {
    return e;
  }
}

Runtime Runtime::adopt(const DeviceHandles& host) {
  return translateErrors(ErrorCode::DeviceUnsupported, [&] {
    gpu::AdoptedDevice d;
    d.instance = host.instance;
    d.physicalDevice = host.physicalDevice;
    d.device = host.device;
    d.queue = host.queue;
    d.queueFamily = host.queueFamily;
    if (!d.instance || !d.physicalDevice || !d.device || !d.queue)
      throw Error(ErrorCode::InvalidArgument,
                  "Runtime::adopt: instance, physical device, device and queue must all be given");
    return Runtime(std::make_shared<RuntimeImpl>(gpu::Context::adopt(d)));
  });
}

Result<Runtime> Runtime::tryAdopt(const DeviceHandles& host) noexcept {
  try {
    return adopt(host);
  } catch (const Error& e) {
    return e;
  }
}

DeviceHandles Runtime::device() const {
  const auto& c = impl_->ctx;
  return {c.instance(), c.physicalDevice(), c.device(), c.queue(), c.queueFamily()};
}
std::string Runtime::deviceName() const { return impl_->ctx.deviceName(); }
bool Runtime::ownsDevice() const { return impl_->ctx.ownsDevice(); }
bool Runtime::supportsNormalMaps() const { return impl_->ctx.supportsNormalMaps(); }

Model Runtime::loadModel(const std::filesystem::path& path) const {
  swish::Model model = translateErrors(ErrorCode::BadModel, [&] { return swish::loadModel(path); });
  return translateErrors(ErrorCode::Internal,
                         [&] { return makeModel(impl_, std::move(model), path.filename().string()); });
}

Result<Model> Runtime::tryLoadModel(const std::filesystem::path& path) const noexcept {
  try {
    return loadModel(path);
  } catch (const Error& e) {
    return e;
  }
}

Model Runtime::loadModelFromMemory(std::span<const uint8_t> bytes, const std::string& name) const {
  swish::Model model = translateErrors(ErrorCode::BadModel, [&] { return swish::deserializeModel(bytes, name); });
  return translateErrors(ErrorCode::Internal, [&] { return makeModel(impl_, std::move(model), name); });
}

std::vector<std::string> Runtime::validationMessages() const { return impl_->ctx.validationMessages(); }
void Runtime::clearValidationMessages() const { impl_->ctx.clearValidationMessages(); }

}  // namespace swish::api
