// libFuzzer target for the .swish loader (deserializeModel), built with clang and ASan + UBSan.
//
// Each input is tried twice:
//  1. as it is: exercises the container checks (magic, version, sizes, checksums), where random
//     mutations almost always stop;
//  2. with its sizes and CRC-32s repaired the way a writer would have set them: this lets mutations
//     reach the section parsers and Model::validate, which checksums would otherwise shield from the
//     fuzzer.
// Loading may fail only with swish::Error. Anything else (a crash, a sanitizer report, another
// exception type, an allocation over -malloc_limit_mb) is a finding. A model that loads must survive
// serialize -> deserialize -> serialize with identical bytes.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "swish/core/error.hpp"
#include "swish/files/crc32.hpp"
#include "swish/model/model_file.hpp"

namespace {

uint64_t getLe(const std::vector<uint8_t>& b, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | b[at + size_t(i)];
  return v;
}

void putLe(std::vector<uint8_t>& b, size_t at, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b[at + size_t(i)] = uint8_t(v >> (8 * i));
}

// Walks the container as documented in model_file.hpp and rewrites the total size, every section's
// payload size (clamped to the bytes present) and checksum, and the header checksum.
std::vector<uint8_t> withRepairedChecksums(std::span<const uint8_t> in) {
  std::vector<uint8_t> b(in.begin(), in.end());
  if (b.size() < swish::kModelFileHeaderBytes) return b;
  putLe(b, 16, b.size(), 8);
  const uint64_t sections = getLe(b, 12, 4);
  size_t pos = swish::kModelFileHeaderBytes;
  for (uint64_t s = 0; s < sections && pos + swish::kModelSectionHeaderBytes <= b.size(); ++s) {
    const size_t payloadAt = pos + swish::kModelSectionHeaderBytes;
    uint64_t size = getLe(b, pos + 4, 8);
    if (size > b.size() - payloadAt) {
      size = b.size() - payloadAt;
      putLe(b, pos + 4, size, 8);
    }
    putLe(b, pos + 12, swish::crc32(std::span<const uint8_t>(b.data() + payloadAt, size_t(size))), 4);
    pos = payloadAt + size_t(size);
  }
  putLe(b, 28, swish::crc32(std::span<const uint8_t>(b.data(), 28)), 4);
  return b;
}

void tryLoad(std::span<const uint8_t> bytes) {
  swish::Model model;
  try {
    model = swish::deserializeModel(bytes, "fuzz.swish");
  } catch (const swish::Error&) {
    return;  // the expected way to refuse a bad file
  }
  // Loaded: the model is valid, so it must write and read back to the same bytes.
  const std::vector<uint8_t> once = swish::serializeModel(model);
  const std::vector<uint8_t> twice = swish::serializeModel(swish::deserializeModel(once, "fuzz-roundtrip.swish"));
  if (once != twice) {
    std::fprintf(stderr, "round trip of a loaded model changed its bytes\n");
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> input(data, size);
  tryLoad(input);
  const std::vector<uint8_t> repaired = withRepairedChecksums(input);
  tryLoad(repaired);
  return 0;
}
