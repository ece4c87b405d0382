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
  void u16(uint16_t v) { put(v, 2); }
  void u32(uint32_t v) { put(v, 4); }
  void u64(uint64_t v) { put(v, 8); }
  void i32(int32_t v) { u32(uint32_t(v)); }
  // The bit pattern is kept exactly (NaN payloads and signed zeros included).
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void f32s(std::span<const float> v) {
    uint8_t* p = grow(4 * v.size());
    for (float x : v) p = store(p, std::bit_cast<uint32_t>(x), 4);
  }
  void u16s(std::span<const uint16_t> v) {
    uint8_t* p = grow(2 * v.size());
    for (uint16_t x : v) p = store(p, x, 2);
  }
  void u32s(std::span<const uint32_t> v) {
    uint8_t* p = grow(4 * v.size());
    for (uint32_t x : v) p = store(p, x, 4);
  }
  void bytes(std::span<const uint8_t> v) { bytes_.insert(bytes_.end(), v.begin(), v.end()); }
  void text(std::string_view s) { bytes_.insert(bytes_.end(), s.begin(), s.end()); }

  size_t size() const { return bytes_.size(); }
  const std::vector<uint8_t>& data() const { return bytes_; }
  std::vector<uint8_t>& data() { return bytes_; }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  // Room for n more bytes at the end; returns where they start.
  uint8_t* grow(size_t n) {
    const size_t at = bytes_.size();
    bytes_.resize(at + n);
    return bytes_.data() + at;
  }
  static uint8_t* store(uint8_t* p, uint64_t v, int n) {
    for (int i = 0; i < n; ++i) *p++ = uint8_t(v >> (8 * i));
    return p;
  }
  void put(uint64_t v, int n) { store(grow(size_t(n)), v, n); }

  std::vector<uint8_t> bytes_;
};

}  // namespace swish
