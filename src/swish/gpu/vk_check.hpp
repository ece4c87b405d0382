#pragma once
// Unexpected VkResults: thrown as swish::Error naming the call, the file and the line. Expected
// failures (no device, missing feature) are reported by the callers with a reason a person can act on.
#include <vulkan/vulkan.h>

#include <string>

#include "swish/core/error.hpp"

// Vulkan info structs are written as `VkXxxInfo x{VK_STRUCTURE_TYPE_...}`: every other member zero is
// the intent, so this warning is noise in the gpu layer's .cpp files (the only includers of this header).
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace swish::gpu {

const char* vkResultName(VkResult r);

[[noreturn]] void throwVkError(VkResult r, const char* call, const char* file, int line);

}  // namespace swish::gpu

#define SWISH_VK(call)                                                                                       \
  do {                                                                                                       \
    const VkResult swishVkResult_ = (call);                                                                  \
    if (swishVkResult_ != VK_SUCCESS) ::swish::gpu::throwVkError(swishVkResult_, #call, __FILE__, __LINE__); \
  } while (0)
