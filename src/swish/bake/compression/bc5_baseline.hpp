#pragma once
// The baseline the VQ database is measured against: every map compressed on its own with BC5 (two
// 8-bit channels per texel reconstructed from two endpoints and 3-bit indices per 4x4 block,
// 16 bytes a block) by libsquish, as a GPU would store it.
#include <cstddef>
#include <utility>

#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

// Bytes of one width x height map in BC5.
size_t bc5Bytes(uint32_t width, uint32_t height);

// Compresses X, Y (unorm8 mapping of [-1, 1]) with BC5 and decodes the result back to float.
NormalMapImage bc5RoundTrip(const NormalMapImage& map);

// The largest square-ish BC5 size (both sides multiples of 4, the map's aspect kept) whose BC5 bytes
// fit in `bytes`: the resolution BC5 can afford with the memory of another scheme (the VQ database's
// share per map). 0x0 when not even one 4x4 block fits.
std::pair<uint32_t, uint32_t> bc5SizeWithin(uint32_t width, uint32_t height, size_t bytes);

// BC5 at a lower resolution: the map box-filtered down to width x height (area-weighted), BC5
// round-tripped there, and sampled back up to the map's own size bilinearly, as a GPU samples a smaller
// texture. The baseline at equal memory: what BC5 gives when it may spend only what VQ spends.
NormalMapImage bc5RoundTripResized(const NormalMapImage& map, uint32_t width, uint32_t height);

}  // namespace swish::bake
