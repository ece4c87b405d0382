#pragma once
// The baseline the VQ database is measured against: every map compressed on its own with BC5 (two
// 8-bit channels per texel reconstructed from two endpoints and 3-bit indices per 4x4 block,
// 16 bytes a block) by libsquish, as a GPU would store it.
#include <cstddef>

#include "swish/bake/dataset.hpp"

namespace swish::bake {

// Bytes of one width x height map in BC5.
size_t bc5Bytes(uint32_t width, uint32_t height);

// Compresses X, Y (unorm8 mapping of [-1, 1]) with BC5 and decodes the result back to float.
NormalMapImage bc5RoundTrip(const NormalMapImage& map);

}  // namespace swish::bake
