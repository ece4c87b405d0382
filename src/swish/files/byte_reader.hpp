#pragma once
// Reads little-endian values from untrusted bytes. Every read is bounds-checked, and every count is
// checked against the bytes that remain BEFORE anything is allocated for it, so a hostile count can
// never cause a huge allocation. Errors name the context (file and section) and the problem, e.g.
//   "model.swish: section 'MESH': triangle count 4294967295 needs 51539607540 bytes but the section
//    has 1200 left"
#include <cstdint>
#include <span>
#include <string>

namespace swish {

class ByteReader {
 public:
  // `context` prefixes every error message ("model.swish: section 'MESH'"); `region` names what the
  // bytes are in "... but the <region> has N left" ("section", "file").
  ByteReader(std::span<const uint8_t> bytes, std::string context, std::string region = "section");

  uint8_t u8(const char* what);
  uint16_t u16(const char* what);
  uint32_t u32(const char* what);
  uint64_t u64(const char* what);
  int32_t i32(const char* what);
  float f32(const char* what);

  // Checks that `count` items of `itemBytes` bytes each fit in what is left; returns count as size_t.
  // Throws "<what> count <count> needs <bytes> bytes but the section has <left> left".
  size_t checkCount(uint64_t count, uint64_t itemBytes, const char* what) const;
  // a * b, or an error naming `what` when the product does not fit in 64 bits.
  uint64_t multiply(uint64_t a, uint64_t b, const char* what) const;

  // Bulk reads; the caller sized the destination after checkCount.
  void f32s(float* out, size_t count, const char* what);
  void u16s(uint16_t* out, size_t count, const char* what);
  void u32s(uint32_t* out, size_t count, const char* what);
  void bytes(uint8_t* out, size_t count, const char* what);
  std::span<const uint8_t> view(size_t count, const char* what);  // no copy
  void skip(size_t count, const char* what);

  size_t remaining() const { return bytes_.size() - pos_; }
  size_t position() const { return pos_; }
  // Everything consumed? Trailing bytes mean the writer and reader disagree: an error.
  void expectEnd() const;

  [[noreturn]] void fail(const std::string& problem) const;
  const std::string& context() const { return context_; }

 private:
  const uint8_t* take(size_t n, const char* what);

  std::span<const uint8_t> bytes_;
  size_t pos_ = 0;
  std::string context_;
  std::string region_;
};

}  // namespace swish
