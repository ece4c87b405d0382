#pragma once
// Appends little-endian values to a byte vector, one byte at a time by shifts, so the output is the
// same on any host and no struct layout or padding ever reaches a file. Used by the .swish writer
// (and by tests that build deliberately broken files).
#include <bit>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace swish {

class ByteWriter {
 public:
  void u8(uint8_t v) { bytes_.push_back(v); }
  void u16(uint16_t v) {
    for (int i = 0; i < 2; ++i) bytes_.push_back(uint8_t(v >> (8 * i)));
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(uint8_t(v >> (8 * i)));
  }
  void u64(uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(uint8_t(v >> (8 * i)));
  }
  void i32(int32_t v) { u32(uint32_t(v)); }
  // The bit pattern is kept exactly (NaN payloads and signed zeros included).
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void f32s(std::span<const float> v) {
    bytes_.reserve(bytes_.size() + 4 * v.size());
    for (float x : v) f32(x);
  }
  void u16s(std::span<const uint16_t> v) {
    for (uint16_t x : v) u16(x);
  }
  void u32s(std::span<const uint32_t> v) {
    for (uint32_t x : v) u32(x);
  }
  void bytes(std::span<const uint8_t> v) { bytes_.insert(bytes_.end(), v.begin(), v.end()); }
  void text(std::string_view s) { bytes_.insert(bytes_.end(), s.begin(), s.end()); }

  size_t size() const { return bytes_.size(); }
  const std::vector<uint8_t>& data() const { return bytes_; }
  std::vector<uint8_t>& data() { return bytes_; }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

}  // namespace swish
