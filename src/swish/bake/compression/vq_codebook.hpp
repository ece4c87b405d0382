#pragma once
// Vector quantisation of the normal-map database (paper 2.2): every 4x4 block of X, Y texels (32
// values) is replaced by a 16-bit index into a shared codebook of snorm8 blocks. Layout as in
// model.hpp's NormalMapDatabase. Training is k-means (k-means++ seeded, LBG-style Lloyd iterations) on
// a deterministic subsample of the blocks; then every block is assigned to the QUANTISED codebook, the
// entries are refitted to all their blocks once and the assignment is repeated, so the error measured
// is the error the runtime will show.
#include <cstdint>
#include <vector>

#include "swish/bake/compression/kmeans.hpp"
#include "swish/bake/dataset/dataset.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct VqOptions {
  uint32_t codebookSize = 4096;     // entries, 1..65536 (16-bit indices)
  uint32_t trainingBlocks = 65536;  // subsample for the Lloyd iterations (0: all blocks)
  int iterations = 25;
  int refinements = 1;  // passes over ALL blocks after training (assign + refit)
  uint64_t seed = 1;
};

struct VqReport {
  uint32_t codebookEntries = 0;  // may be below codebookSize when there are fewer distinct blocks
  uint64_t blocks = 0;
  uint64_t codebookBytes = 0;
  uint64_t indexBytes = 0;
  uint64_t totalBytes() const { return codebookBytes + indexBytes; }
  double trainingSeconds = 0.0;
  double assignmentSeconds = 0.0;
  int iterations = 0;
};

// All 4x4 blocks of the maps, one row each (32 floats: texel t = (y%4)*4 + x%4, X then Y), map by map,
// block rows top to bottom. Maps must share a size that is a multiple of 4.
RowMatXf extractBlocks(const std::vector<const NormalMapImage*>& maps);

// Trains the codebook and fills db.width/height/codebookSize/codebook/indices (db.keys untouched).
VqReport encodeVq(const std::vector<const NormalMapImage*>& maps, const VqOptions& options, NormalMapDatabase& db);

// Decodes map m of a database exactly as model.hpp specifies (the runtime's VQ decode).
NormalMapImage decodeVqMap(const NormalMapDatabase& db, uint32_t map);

inline int8_t toSnorm8(float v) {
  v = v < -1.f ? -1.f : (v > 1.f ? 1.f : v);
  const float s = v * 127.f;
  return int8_t(s < 0.f ? s - 0.5f : s + 0.5f);
}

}  // namespace swish::bake
