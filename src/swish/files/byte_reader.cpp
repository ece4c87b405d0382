#include "swish/files/byte_reader.hpp"

#include <bit>
#include <limits>

#include "swish/core/error.hpp"

namespace swish {

ByteReader::ByteReader(std::span<const uint8_t> bytes, std::string context, std::string region)
    : bytes_(bytes), context_(std::move(context)), region_(std::move(region)) {}

void ByteReader::fail(const std::string& problem) const { throw Error(context_ + ": " + problem); }

const uint8_t* ByteReader::take(size_t n, const char* what) {
  if (n > remaining())
    fail(std::string(what) + " needs " + std::to_string(n) + " bytes but the " + region_ + " has " +
         std::to_string(remaining()) + " left");
  const uint8_t* p = bytes_.data() + pos_;
  pos_ += n;
  return p;
}

uint8_t ByteReader::u8(const char* what) { return *take(1, what); }

uint16_t ByteReader::u16(const char* what) {
  const uint8_t* p = take(2, what);
  return uint16_t(p[0] | p[1] << 8);
}

uint32_t ByteReader::u32(const char* what) {
  const uint8_t* p = take(4, what);
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

uint64_t ByteReader::u64(const char* what) {
  const uint8_t* p = take(8, what);
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

int32_t ByteReader::i32(const char* what) { return int32_t(u32(what)); }

float ByteReader::f32(const char* what) { return std::bit_cast<float>(u32(what)); }

uint64_t ByteReader::multiply(uint64_t a, uint64_t b, const char* what) const {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r))
    fail(std::string(what) + " count " + std::to_string(a) + " x " + std::to_string(b) + " overflows 64 bits");
  return r;
}

size_t ByteReader::checkCount(uint64_t count, uint64_t itemBytes, const char* what) const {
  uint64_t need;
  const bool overflow = __builtin_mul_overflow(count, itemBytes, &need);
  if (overflow || need > remaining())
    fail(std::string(what) + " count " + std::to_string(count) + " needs " +
         (overflow ? std::string("more than 2^64") : std::to_string(need)) + " bytes but the " + region_ + " has " +
         std::to_string(remaining()) + " left");
  return size_t(count);
}

void ByteReader::f32s(float* out, size_t count, const char* what) {
  const uint8_t* p = take(checkCount(count, 4, what) * 4, what);
  for (size_t i = 0; i < count; ++i, p += 4)
    out[i] = std::bit_cast<float>(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24);
}

void ByteReader::u16s(uint16_t* out, size_t count, const char* what) {
  const uint8_t* p = take(checkCount(count, 2, what) * 2, what);
  for (size_t i = 0; i < count; ++i, p += 2) out[i] = uint16_t(p[0] | p[1] << 8);
}

void ByteReader::u32s(uint32_t* out, size_t count, const char* what) {
  const uint8_t* p = take(checkCount(count, 4, what) * 4, what);
  for (size_t i = 0; i < count; ++i, p += 4)
    out[i] = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

void ByteReader::bytes(uint8_t* out, size_t count, const char* what) {
  const uint8_t* p = take(checkCount(count, 1, what), what);
  for (size_t i = 0; i < count; ++i) out[i] = p[i];
}

std::span<const uint8_t> ByteReader::view(size_t count, const char* what) {
  return {take(checkCount(count, 1, what), what), count};
}

void ByteReader::skip(size_t count, const char* what) { take(checkCount(count, 1, what), what); }

void ByteReader::expectEnd() const {
  if (remaining() != 0) fail(std::to_string(remaining()) + " unexpected bytes after the last field");
}

}  // namespace swish
