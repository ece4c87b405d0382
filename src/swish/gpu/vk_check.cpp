#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

const char* vkResultName(VkResult r) {
  switch (r) {
#define SWISH_CASE(x) \
  case x:             \
    return #x;
    SWISH_CASE(VK_SUCCESS)
    SWISH_CASE(VK_NOT_READY)
    SWISH_CASE(VK_TIMEOUT)
    SWISH_CASE(VK_INCOMPLETE)
    SWISH_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SWISH_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SWISH_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SWISH_CASE(VK_ERROR_DEVICE_LOST)
    SWISH_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SWISH_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SWISH_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SWISH_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SWISH_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SWISH_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SWISH_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SWISH_CASE(VK_ERROR_FRAGMENTED_POOL)
    SWISH_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    SWISH_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    SWISH_CASE(VK_ERROR_FRAGMENTATION)
    SWISH_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
#undef SWISH_CASE
    default:
      return "VkResult(unknown)";
  }
}

void throwVkError(VkResult r, const char* call, const char* file, int line) {
  throw Error(std::string("Vulkan call failed: ") + call + " returned " + vkResultName(r) + " (" +
              std::to_string(int(r)) + ") at " + file + ":" + std::to_string(line));
}

}  // namespace swish::gpu
