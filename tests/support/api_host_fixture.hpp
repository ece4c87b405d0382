#pragma once
// Shared by the API and preview tests: a host-made Vulkan device (render::HostDevice, the way a host
// renderer makes one) with the validation layer on (unless SWISH_VALIDATION=0) and every validation
// message failing the test; skipped with the reason when there is no usable device, FAILED instead
// when SWISH_REQUIRE_GPU=1 (CI). Plus the stand-in jersey model and the default mannequin.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "swish/bake/character/default_character.hpp"
#include "swish/model/model_file.hpp"
#include "swish/render/host_device.hpp"
#include "swish/replay/procedural_model.hpp"
#include "swish/swish.hpp"

namespace swish::test {

inline render::HostDeviceOptions hostDeviceOptions() {
  render::HostDeviceOptions o;
  const char* v = std::getenv("SWISH_VALIDATION");
  o.validation = !(v && std::string(v) == "0");
  return o;
}

// Makes a host device, or skips/fails the current test. Returns nullptr when skipped or failed.
inline std::unique_ptr<render::HostDevice> makeHostDeviceOrSkip() {
  try {
    return std::make_unique<render::HostDevice>(hostDeviceOptions());
  } catch (const api::Error& e) {
    const char* req = std::getenv("SWISH_REQUIRE_GPU");
    if (req && std::string(req) == "1") {
      ADD_FAILURE() << "no usable Vulkan device and SWISH_REQUIRE_GPU=1: " << e.what();
    } else {
      std::printf("GPU test skipped: %s\n", e.what());
    }
    return nullptr;
  }
}

#define SWISH_HOST_DEVICE_OR_SKIP(var)                                 \
  auto var = ::swish::test::makeHostDeviceOrSkip();                    \
  if (!var) {                                                          \
    if (::testing::Test::HasFailure()) return;                         \
    GTEST_SKIP() << "no usable Vulkan device (see the message above)"; \
  }

inline void expectNoValidationMessages(const render::HostDevice& d) {
  const auto m = d.validationMessages();
  EXPECT_EQ(m.size(), 0u) << "Vulkan validation messages";
  for (size_t i = 0; i < m.size() && i < 8; ++i) ADD_FAILURE() << m[i];
}

// The default mannequin (made by code) and a jersey-shaped stand-in model on its skeleton: small
// sizes so that lavapipe renders a frame in well under a second.
inline const Character& defaultCharacter() {
  static const Character c = bake::makeDefaultCharacter();
  return c;
}

inline Model standInJersey() {
  replay::ProceduralModelSpec spec;
  spec.rings = 24;
  spec.segments = 40;
  spec.meshComponents = 8;
  spec.normalMaps = 4;
  spec.codeDims = 4;
  spec.mapSize = 64;
  spec.codebookSize = 64;
  return replay::makeProceduralModel(defaultCharacter().skeleton, spec);
}

}  // namespace swish::test
