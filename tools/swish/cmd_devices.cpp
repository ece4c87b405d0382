// swish devices: lists the Vulkan devices, whether swish can use each, and which one it would pick
// (SWISH_DEVICE or --device override the automatic choice: discrete, integrated, virtual, CPU).
#include <cstdio>

#include "swish/command.hpp"
#include "swish/gpu/context.hpp"

namespace {

struct DevicesOptions {
  std::string device;
};

swish::cli::RunFn setup(CLI::App& app) {
  auto o = std::make_shared<DevicesOptions>();
  app.add_option("--device", o->device,
                 "Device to select: index or name substring (default: SWISH_DEVICE, else automatic)");
  return [o]() {
    swish::gpu::ContextOptions co;
    co.device = o->device;
    int picked = -1;
    std::string why;
    const auto devices = swish::gpu::Context::listDevices(co, picked, why);
    if (devices.empty()) std::printf("no Vulkan devices\n");
    for (const auto& d : devices)
      std::printf("%c %u: %s (%s, Vulkan %u.%u)%s%s\n", int(d.index) == picked ? '*' : ' ', d.index, d.name.c_str(),
                  swish::gpu::deviceTypeName(d.type), VK_API_VERSION_MAJOR(d.apiVersion),
                  VK_API_VERSION_MINOR(d.apiVersion),
                  d.usable ? "" : " - unusable: ", d.usable ? "" : d.unusableReason.c_str());
    if (picked < 0) {
      std::printf("no device would be picked: %s\n", why.c_str());
      return 1;
    }
    std::printf(
        "swish would use device %d (* above); override with --device or SWISH_DEVICE (index or name substring)\n",
        picked);
    return 0;
  };
}

swish::cli::CommandRegistration reg{"devices", "List Vulkan devices and which one swish would pick", setup};

}  // namespace
