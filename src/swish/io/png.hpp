#pragma once
// PNG images, 8 or 16 bits per channel, 1 (gray), 2 (gray + alpha, used as RG), 3 (RGB) or 4 (RGBA)
// channels, and the project's normal-map encoding on top of them.
//
// Writing: our own PNG container (signature, IHDR, one IDAT, IEND, CRC-32 per chunk) around stb's
// deflate (stbi_zlib_compress from stb_image_write.h), with the per-row filter chosen by the usual
// "smallest sum of absolute differences" heuristic. stb_image_write has no 16-bit PNG writer, which is
// why the container is ours; 8-bit goes through the same code so both depths behave alike. 16-bit
// samples are stored big-endian as PNG requires. Files are written atomically (temporary file in the
// same folder, then rename), so a reader never sees half an image.
// Reading: stb_image.h (stbi_load_16_from_memory / stbi_load_from_memory), keeping the file's depth
// and channel count. Every failure throws swish::Error naming the file.
//
// Normal maps (see bake::NormalMapImage): tangent-space X, Y in [-1, 1] are stored as unorm
// v * 0.5 + 0.5 in red and green; blue holds Z = sqrt(max(0, 1 - X^2 - Y^2)) encoded the same way
// (so the file looks like an ordinary tangent-space normal map in any viewer; readers ignore it and
// rebuild Z from X, Y). Rounding is to nearest: the quantisation error is at most 1/(2^bits - 1) per
// component, about 1.5e-5 at 16 bits and 3.9e-3 at 8 bits.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace swish::io {

struct PngImage {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;  // 1..4
  uint32_t bitDepth = 8;  // 8 or 16
  // Row-major from the top row of the file, channels interleaved; values in [0, 2^bitDepth - 1].
  std::vector<uint16_t> samples;

  uint16_t maxValue() const { return bitDepth == 16 ? 65535 : 255; }
  uint16_t& at(uint32_t x, uint32_t y, uint32_t c) { return samples[(size_t(y) * width + x) * channels + c]; }
  uint16_t at(uint32_t x, uint32_t y, uint32_t c) const { return samples[(size_t(y) * width + x) * channels + c]; }
};

// Checks the image is consistent (sizes, depth, channels, sample range); throws Error naming `what`.
void validatePngImage(const PngImage& image, const std::string& what);

// Encodes to PNG bytes in memory / decodes PNG bytes (`what` names the source in error messages).
std::vector<uint8_t> encodePng(const PngImage& image);
PngImage decodePng(std::span<const uint8_t> bytes, const std::string& what);

// Atomic write; read with errors naming the file.
void writePng(const std::filesystem::path& path, const PngImage& image);
PngImage readPng(const std::filesystem::path& path);

// Normal maps: xy holds 2 floats per texel (row-major, row 0 first), X and Y in [-1, 1] (clamped).
// Produces an RGB image of the given depth with the encoding documented above.
PngImage encodeNormalMap(uint32_t width, uint32_t height, std::span<const float> xy, uint32_t bitDepth);
// Back to 2 floats per texel from red and green; needs >= 2 channels. `what` names the source.
std::vector<float> decodeNormalMap(const PngImage& image, const std::string& what);

}  // namespace swish::io
