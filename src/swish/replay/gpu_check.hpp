#pragma once
// Numerical error of one character's GPU outputs against the CPU reference of the same frame.
#include <cstdint>

#include "swish/replay/replay_engine.hpp"
#include "swish/runtime/reference_frame.hpp"

namespace swish::replay {

// Instance `instance` of both outputs (positions always; normals, tangents and maps when the GPU
// produced them). Fills `check` and sets check.ok against the tolerances of replay_engine.hpp.
CharacterCheck compareInstance(const runtime::ReferenceFrameOutputs& gpu, const runtime::ReferenceFrameOutputs& cpu,
                               uint32_t instance, uint32_t character);

}  // namespace swish::replay
