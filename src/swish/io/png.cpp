#include "swish/io/png.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>

#include <unistd.h>

#include "swish/core/error.hpp"
#include "swish/files/crc32.hpp"

// stb in static mode: its symbols stay private to this file, so another file of the project may use
// stb too without duplicate-symbol clashes.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>

namespace swish::io {
namespace {

constexpr uint32_t kMaxDimension = 1u << 15;  // 32768: far beyond any normal map or preview

void putU32(std::vector<uint8_t>& out, uint32_t v) {
  out.push_back(uint8_t(v >> 24));
  out.push_back(uint8_t(v >> 16));
  out.push_back(uint8_t(v >> 8));
  out.push_back(uint8_t(v));
}

void putChunk(std::vector<uint8_t>& out, const char type[4], const uint8_t* data, size_t n) {
  putU32(out, uint32_t(n));
  const size_t typeAt = out.size();
  out.insert(out.end(), type, type + 4);
  if (n) out.insert(out.end(), data, data + n);
  putU32(out, crc32({out.data() + typeAt, n + 4}));
}

uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return uint8_t(a);
  return pb <= pc ? uint8_t(b) : uint8_t(c);
}

// Filters one row (bytes `row`, previous row `prev` or null) with filter type `f` into `out`.
void filterRow(int f, const uint8_t* row, const uint8_t* prev, size_t n, size_t bpp, uint8_t* out) {
  for (size_t i = 0; i < n; ++i) {
    const int a = i >= bpp ? row[i - bpp] : 0, b = prev ? prev[i] : 0;
    const int c = (prev && i >= bpp) ? prev[i - bpp] : 0;
    int pred = 0;
    switch (f) {
      case 1:
        pred = a;
        break;
      case 2:
        pred = b;
        break;
      case 3:
        pred = (a + b) >> 1;
        break;
      case 4:
        pred = paeth(a, b, c);
        break;
      default:
        pred = 0;
        break;
    }
    out[i] = uint8_t(row[i] - pred);
  }
}

std::vector<uint8_t> readWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("PNG " + path.string() + ": cannot open the file for reading");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw Error("PNG " + path.string() + ": cannot determine the file size");
  in.seekg(0);
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (size && !in.read(reinterpret_cast<char*>(bytes.data()), size))
    throw Error("PNG " + path.string() + ": read failed");
  return bytes;
}

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

}  // namespace

void validatePngImage(const PngImage& im, const std::string& what) {
  if (im.width == 0 || im.height == 0 || im.width > kMaxDimension || im.height > kMaxDimension)
    throw Error(what + ": image size " + std::to_string(im.width) + "x" + std::to_string(im.height) +
                " is outside 1.." + std::to_string(kMaxDimension));
  if (im.channels < 1 || im.channels > 4)
    throw Error(what + ": " + std::to_string(im.channels) + " channels (PNG supports 1 to 4)");
  if (im.bitDepth != 8 && im.bitDepth != 16)
    throw Error(what + ": bit depth " + std::to_string(im.bitDepth) + " (supported: 8, 16)");
  const size_t expect = size_t(im.width) * im.height * im.channels;
  if (im.samples.size() != expect)
    throw Error(what + ": " + std::to_string(im.samples.size()) + " samples for " + std::to_string(im.width) + "x" +
                std::to_string(im.height) + "x" + std::to_string(im.channels) + " (" + std::to_string(expect) +
                " expected)");
  if (im.bitDepth == 8)
    for (uint16_t s : im.samples)
      if (s > 255) throw Error(what + ": sample value " + std::to_string(s) + " does not fit 8 bits");
}

std::vector<uint8_t> encodePng(const PngImage& im) {
  validatePngImage(im, "PNG encode");
  const size_t bytesPerSample = im.bitDepth / 8, bpp = im.channels * bytesPerSample;
  const size_t rowBytes = size_t(im.width) * bpp;

  // Raw rows (big-endian samples), then per row the filter with the smallest sum of |signed bytes|.
  std::vector<uint8_t> raw(rowBytes * im.height);
  for (size_t i = 0; i < im.samples.size(); ++i) {
    if (bytesPerSample == 2) {
      raw[2 * i] = uint8_t(im.samples[i] >> 8);
      raw[2 * i + 1] = uint8_t(im.samples[i] & 0xFF);
    } else {
      raw[i] = uint8_t(im.samples[i]);
    }
  }
  std::vector<uint8_t> filtered((rowBytes + 1) * im.height);
  std::vector<uint8_t> trial(rowBytes);
  for (uint32_t y = 0; y < im.height; ++y) {
    const uint8_t* row = raw.data() + y * rowBytes;
    const uint8_t* prev = y ? row - rowBytes : nullptr;
    int bestFilter = 0;
    uint64_t bestScore = UINT64_MAX;
    for (int f = 0; f < 5; ++f) {
      filterRow(f, row, prev, rowBytes, bpp, trial.data());
      uint64_t score = 0;
      for (uint8_t b : trial) score += uint64_t(std::abs(int(int8_t(b))));
      if (score < bestScore) bestScore = score, bestFilter = f;
    }
    uint8_t* out = filtered.data() + y * (rowBytes + 1);
    out[0] = uint8_t(bestFilter);
    filterRow(bestFilter, row, prev, rowBytes, bpp, out + 1);
  }

  if (filtered.size() > size_t(INT32_MAX)) throw Error("PNG encode: image too large for one IDAT stream");
  int zlen = 0;
  std::unique_ptr<unsigned char, decltype(&std::free)> z(
      stbi_zlib_compress(filtered.data(), int(filtered.size()), &zlen, 8), &std::free);
  if (!z || zlen <= 0) throw Error("PNG encode: deflate failed (out of memory?)");

  static const uint8_t kColorType[5] = {0, 0, 4, 2, 6};  // by channel count: gray, gray+alpha, RGB, RGBA
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> ihdr;
  putU32(ihdr, im.width);
  putU32(ihdr, im.height);
  ihdr.push_back(uint8_t(im.bitDepth));
  ihdr.push_back(kColorType[im.channels]);
  ihdr.push_back(0);  // deflate
  ihdr.push_back(0);  // adaptive filtering
  ihdr.push_back(0);  // no interlace
  putChunk(png, "IHDR", ihdr.data(), ihdr.size());
  putChunk(png, "IDAT", z.get(), size_t(zlen));
  putChunk(png, "IEND", nullptr, 0);
  return png;
}

PngImage decodePng(std::span<const uint8_t> bytes, const std::string& what) {
  static const uint8_t kSig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSig, 8) != 0)
    throw Error(what + ": not a PNG file (bad signature)");
  if (bytes.size() > size_t(INT32_MAX)) throw Error(what + ": file too large");
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int len = int(bytes.size());
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(data, len, &w, &h, &comp))
    throw Error(what + ": cannot read the PNG header (" + std::string(stbi_failure_reason()) + ")");
  if (w <= 0 || h <= 0 || uint32_t(w) > kMaxDimension || uint32_t(h) > kMaxDimension)
    throw Error(what + ": image size " + std::to_string(w) + "x" + std::to_string(h) + " is outside 1.." +
                std::to_string(kMaxDimension));
  PngImage im;
  im.bitDepth = stbi_is_16_bit_from_memory(data, len) ? 16 : 8;
  if (im.bitDepth == 16) {
    std::unique_ptr<stbi_us, StbFree> px(stbi_load_16_from_memory(data, len, &w, &h, &comp, 0));
    if (!px) throw Error(what + ": corrupt PNG (" + std::string(stbi_failure_reason()) + ")");
    im.samples.assign(px.get(), px.get() + size_t(w) * h * comp);
  } else {
    std::unique_ptr<stbi_uc, StbFree> px(stbi_load_from_memory(data, len, &w, &h, &comp, 0));
    if (!px) throw Error(what + ": corrupt PNG (" + std::string(stbi_failure_reason()) + ")");
    im.samples.assign(px.get(), px.get() + size_t(w) * h * comp);
  }
  im.width = uint32_t(w);
  im.height = uint32_t(h);
  im.channels = uint32_t(comp);
  return im;
}

void writePng(const std::filesystem::path& path, const PngImage& image) {
  const std::vector<uint8_t> bytes = encodePng(image);
  // Atomic: write a temporary file beside the target, then rename over it.
  std::filesystem::path tmp = path;
  static std::atomic<uint64_t> counter{0};
  tmp += ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter.fetch_add(1));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("PNG " + path.string() + ": cannot open a temporary file for writing");
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw Error("PNG " + path.string() + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error("PNG " + path.string() + ": cannot rename the temporary file into place");
  }
}

PngImage readPng(const std::filesystem::path& path) {
  const std::vector<uint8_t> bytes = readWholeFile(path);
  return decodePng(bytes, "PNG " + path.string());
}

PngImage encodeNormalMap(uint32_t width, uint32_t height, std::span<const float> xy, uint32_t bitDepth) {
  if (xy.size() != size_t(width) * height * 2)
    throw Error("normal map encode: " + std::to_string(xy.size()) + " floats for " + std::to_string(width) + "x" +
                std::to_string(height) + " texels (2 per texel expected)");
  if (bitDepth != 8 && bitDepth != 16)
    throw Error("normal map encode: bit depth " + std::to_string(bitDepth) + " (supported: 8, 16)");
  PngImage im;
  im.width = width;
  im.height = height;
  im.channels = 3;
  im.bitDepth = bitDepth;
  im.samples.resize(size_t(width) * height * 3);
  const float maxv = float(im.maxValue());
  auto unorm = [maxv](float v) {
    if (!std::isfinite(v)) v = 0.f;  // a NaN must not become garbage in the file
    v = std::clamp(v, -1.f, 1.f);
    return uint16_t(std::lround((v * 0.5f + 0.5f) * maxv));
  };
  for (size_t t = 0; t < size_t(width) * height; ++t) {
    const float x = xy[2 * t], y = xy[2 * t + 1];
    const float fx = std::isfinite(x) ? std::clamp(x, -1.f, 1.f) : 0.f;
    const float fy = std::isfinite(y) ? std::clamp(y, -1.f, 1.f) : 0.f;
    const float z = std::sqrt(std::max(0.f, 1.f - fx * fx - fy * fy));
    im.samples[3 * t] = unorm(fx);
    im.samples[3 * t + 1] = unorm(fy);
    im.samples[3 * t + 2] = unorm(z);
  }
  return im;
}

std::vector<float> decodeNormalMap(const PngImage& im, const std::string& what) {
  validatePngImage(im, what);
  if (im.channels < 2)
    throw Error(what + ": a normal map needs at least 2 channels (X, Y), this image has " +
                std::to_string(im.channels));
  const float inv = 1.f / float(im.maxValue());
  std::vector<float> xy(size_t(im.width) * im.height * 2);
  for (size_t t = 0; t < size_t(im.width) * im.height; ++t) {
    xy[2 * t] = float(im.samples[t * im.channels]) * inv * 2.f - 1.f;
    xy[2 * t + 1] = float(im.samples[t * im.channels + 1]) * inv * 2.f - 1.f;
  }
  return xy;
}

}  // namespace swish::io
