#pragma once
// CRC-32 as in zlib, PNG and Ethernet (IEEE 802.3: reflected polynomial 0xEDB88320, initial value and
// final xor 0xFFFFFFFF). crc32("123456789") == 0xCBF43926. Guards every section of a .swish file.
#include <cstdint>
#include <span>

namespace swish {

// `crc` continues a previous result, so crc32(b, crc32(a)) == crc32(a followed by b).
uint32_t crc32(std::span<const uint8_t> bytes, uint32_t crc = 0);

}  // namespace swish
