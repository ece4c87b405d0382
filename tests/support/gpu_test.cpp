#include "support/gpu_test.hpp"

#include <cstdlib>
#include <memory>

namespace swish::test {

gpu::ContextOptions gpuTestOptions() {
  gpu::ContextOptions o;
  const char* v = std::getenv("SWISH_VALIDATION");
  o.validation = !(v && std::string(v) == "0");
  o.applicationName = "swish tests";
  return o;
}

gpu::Context* sharedGpuContext(std::string& whyNot) {
  static std::unique_ptr<gpu::Context> ctx;
  static std::string error;
  static bool tried = false;
  if (!tried) {
    tried = true;
    auto made = gpu::Context::tryCreate(gpuTestOptions());
    if (made) {
      ctx = std::make_unique<gpu::Context>(std::move(made.value()));
      std::printf("[ gpu      ] device: %s (%s), validation %s\n", ctx->deviceName().c_str(),
                  gpu::deviceTypeName(ctx->properties().deviceType), ctx->validationEnabled() ? "on" : "off");
    } else {
      error = made.error().what();
    }
  }
  whyNot = error;
  return ctx.get();
}

void GpuTest::SetUp() {
  std::string why;
  ctx_ = sharedGpuContext(why);
  if (!ctx_) {
    const char* req = std::getenv("SWISH_REQUIRE_GPU");
    if (req && std::string(req) == "1") FAIL() << "no usable Vulkan device and SWISH_REQUIRE_GPU=1: " << why;
    GTEST_SKIP() << "GPU test skipped: no usable Vulkan device (" << why
                 << "). Install a Vulkan driver (lavapipe: mesa-vulkan-drivers) or set SWISH_DEVICE.";
  }
  ctx_->clearValidationMessages();
}

void GpuTest::TearDown() {
  if (!ctx_) return;
  const auto messages = ctx_->validationMessages();
  EXPECT_EQ(messages.size(), 0u) << "Vulkan validation messages during the test";
  for (size_t i = 0; i < messages.size() && i < 10; ++i) ADD_FAILURE() << messages[i];
}

}  // namespace swish::test
