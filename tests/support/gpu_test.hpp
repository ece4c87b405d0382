#pragma once
// GoogleTest support for GPU tests. GpuTest (a fixture) runs each test on the Vulkan device chosen by
// SWISH_DEVICE (index or name substring; default: the automatic choice, lavapipe here) with the
// validation layers ON (unless SWISH_VALIDATION=0 is set explicitly); any validation message fails
// the test. With no usable Vulkan device the test is SKIPPED with the reason, unless
// SWISH_REQUIRE_GPU=1 (set by tools/test.sh in CI), where it FAILS.
#include <gtest/gtest.h>

#include <string>

#include "swish/gpu/context.hpp"

namespace swish::test {

// The process-wide test context (created on first use), or nullptr with the reason in `whyNot`.
gpu::Context* sharedGpuContext(std::string& whyNot);

// The options tests create contexts with (SWISH_DEVICE honoured; validation on unless SWISH_VALIDATION=0).
gpu::ContextOptions gpuTestOptions();

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  gpu::Context& ctx() { return *ctx_; }

 private:
  gpu::Context* ctx_ = nullptr;
};

}  // namespace swish::test
