#pragma once
// SPIR-V modules compiled from shaders/ at build time and linked into the library.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace swish::shaders {

struct EmbeddedShader {
  const char* name;       // file name in shaders/, e.g. "deform.comp"
  const uint32_t* words;  // SPIR-V words
  size_t wordCount;
};

std::span<const EmbeddedShader> all();
const EmbeddedShader* find(std::string_view name);  // nullptr if absent

}  // namespace swish::shaders
