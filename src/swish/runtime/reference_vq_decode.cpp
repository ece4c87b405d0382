#include "swish/runtime/reference_vq_decode.hpp"

#include "swish/core/error.hpp"

namespace swish::runtime {

DecodedNormalMap referenceVqDecode(const NormalMapDatabase& db, uint32_t map) {
  if (map >= db.mapCount())
    throw Error("VQ decode: map " + std::to_string(map) + " is not in the database of " +
                std::to_string(db.mapCount()));
  DecodedNormalMap out;
  out.width = db.width;
  out.height = db.height;
  out.xy.assign(size_t(db.width) * db.height * 2, 0);
  const uint32_t blocksPerRow = db.width / 4;
  for (uint32_t y = 0; y < db.height; ++y)
    for (uint32_t x = 0; x < db.width; ++x) {
      const uint32_t block = (y / 4) * blocksPerRow + x / 4;
      const uint32_t entry = db.indices[size_t(map) * db.blocksPerMap() + block];
      if (entry >= db.codebookSize) continue;
      const uint32_t texel = (y % 4) * 4 + x % 4;
      const size_t o = (size_t(y) * db.width + x) * 2;
      out.xy[o] = db.codebook[(size_t(entry) * 16 + texel) * 2];
      out.xy[o + 1] = db.codebook[(size_t(entry) * 16 + texel) * 2 + 1];
    }
  return out;
}

}  // namespace swish::runtime
