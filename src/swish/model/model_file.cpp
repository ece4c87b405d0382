#include "swish/model/model_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <set>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/byte_reader.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/files/crc32.hpp"
#include "swish/model/model_sections.hpp"

namespace swish {

namespace {

using model_sections::SectionCodec;
using model_sections::sectionCodecs;

const SectionCodec* findCodec(std::string_view tag) {
  for (const auto& c : sectionCodecs())
    if (c.tag == tag) return &c;
  return nullptr;
}

// A tag as it may appear in a message: printable ASCII as is, anything else as \xNN.
std::string printableTag(std::span<const uint8_t> tag) {
  std::string s;
  for (uint8_t c : tag) {
    if (c >= 0x20 && c < 0x7F) {
      s.push_back(char(c));
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      s += hex;
    }
  }
  return s;
}

std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

std::string versionText(uint16_t major, uint16_t minor) { return std::to_string(major) + "." + std::to_string(minor); }

std::vector<uint8_t> serializeValidated(const Model& model) {
  const auto& codecs = sectionCodecs();
  ByteWriter out;
  out.bytes(kModelFileMagic);
  out.u16(kModelFileMajorVersion);
  out.u16(kModelFileMinorVersion);
  out.u32(uint32_t(codecs.size()));
  out.u64(0);  // total size, patched below
  out.u32(0);  // reserved
  out.u32(0);  // header checksum, patched below
  for (const auto& codec : codecs) {
    ByteWriter payload;
    codec.write(model, payload);
    out.text(codec.tag);
    out.u64(payload.size());
    out.u32(crc32(payload.data()));
    out.bytes(payload.data());
  }
  std::vector<uint8_t> bytes = out.take();
  const uint64_t total = bytes.size();
  for (int i = 0; i < 8; ++i) bytes[16 + i] = uint8_t(total >> (8 * i));
  const uint32_t headerCrc = crc32(std::span<const uint8_t>(bytes.data(), 28));
  for (int i = 0; i < 4; ++i) bytes[28 + i] = uint8_t(headerCrc >> (8 * i));
  return bytes;
}

}  // namespace

ModelFileInfo readModelFileInfo(std::span<const uint8_t> bytes, const std::string& sourceName) {
  auto fail = [&](const std::string& problem) -> void { throw Error(sourceName + ": " + problem); };
  if (bytes.size() >= kModelFileMagic.size() &&
      !std::equal(kModelFileMagic.begin(), kModelFileMagic.end(), bytes.begin()))
    fail("not a .swish model file (wrong magic bytes)");
  if (bytes.size() < kModelFileHeaderBytes)
    fail("file is " + std::to_string(bytes.size()) + " bytes, too short for the " +
         std::to_string(kModelFileHeaderBytes) + "-byte header of a .swish model (truncated?)");

  ByteReader header(bytes.first(kModelFileHeaderBytes), sourceName + ": header", "header");
  header.skip(kModelFileMagic.size(), "magic");
  ModelFileInfo info;
  info.majorVersion = header.u16("major version");
  info.minorVersion = header.u16("minor version");
  // The version is checked before the header checksum: a future major version may lay out the rest
  // of its header differently, and "too new" is the useful message then.
  if (info.majorVersion > kModelFileMajorVersion)
    fail("format version " + versionText(info.majorVersion, info.minorVersion) + " is newer than this swish reads (" +
         std::to_string(kModelFileMajorVersion) + ".x); use a newer swish");
  if (info.majorVersion < kModelFileMajorVersion)
    fail("format version " + versionText(info.majorVersion, info.minorVersion) +
         " is not supported (this swish reads " + std::to_string(kModelFileMajorVersion) + ".x)");
  const uint32_t sectionCount = header.u32("section count");
  info.totalBytes = header.u64("total size");
  header.u32("reserved");
  const uint32_t storedHeaderCrc = header.u32("header checksum");
  const uint32_t headerCrc = crc32(bytes.first(28));
  if (storedHeaderCrc != headerCrc)
    fail("header checksum mismatch (stored " + hex32(storedHeaderCrc) + ", computed " + hex32(headerCrc) +
         "): the file is corrupted");
  if (info.totalBytes != bytes.size())
    fail("header says the file is " + std::to_string(info.totalBytes) + " bytes but it is " +
         std::to_string(bytes.size()) +
         (info.totalBytes > bytes.size() ? " (truncated)" : " (extra bytes at the end)"));

  ByteReader body(bytes.subspan(kModelFileHeaderBytes), sourceName, "file");
  body.checkCount(sectionCount, kModelSectionHeaderBytes, "section");
  std::set<std::string> seen;
  for (uint32_t s = 0; s < sectionCount; ++s) {
    ModelFileSection sec;
    sec.offset = kModelFileHeaderBytes + body.position();
    const auto tagBytes = body.view(4, "section tag");
    sec.tag = printableTag(tagBytes);
    const std::string where = "section " + std::to_string(s) + " ('" + sec.tag + "')";
    if (sec.tag.size() != 4) fail(where + ": the tag is not printable ASCII");
    sec.payloadBytes = body.u64("section payload size");
    sec.crc = body.u32("section checksum");
    if (sec.payloadBytes > body.remaining())
      fail(where + ": payload of " + std::to_string(sec.payloadBytes) + " bytes but the file has " +
           std::to_string(body.remaining()) + " left");
    const auto payload = body.view(size_t(sec.payloadBytes), "section payload");
    const uint32_t crc = crc32(payload);
    if (crc != sec.crc)
      fail("section '" + sec.tag + "': checksum mismatch (stored " + hex32(sec.crc) + ", computed " + hex32(crc) +
           "): the file is corrupted");
    if (!seen.insert(sec.tag).second) fail("section '" + sec.tag + "' appears twice");
    const SectionCodec* codec = findCodec(sec.tag);
    sec.known = codec != nullptr;
    if (codec && codec->sinceMinor > info.minorVersion)
      fail(where + ": a section of format " + versionText(kModelFileMajorVersion, codec->sinceMinor) +
           " in a version " + versionText(info.majorVersion, info.minorVersion) + " file");
    // Sections unknown to this reader are legitimate only in a file of a newer minor version.
    if (!sec.known && info.minorVersion <= kModelFileMinorVersion)
      fail("unknown section '" + sec.tag + "' in a version " + versionText(info.majorVersion, info.minorVersion) +
           " file");
    info.sections.push_back(std::move(sec));
  }
  if (body.remaining() != 0) fail(std::to_string(body.remaining()) + " bytes after the last section");
  for (const auto& codec : sectionCodecs())
    if (!seen.count(std::string(codec.tag)) && codec.sinceMinor <= info.minorVersion)
      fail("section '" + std::string(codec.tag) + "' is missing");
  return info;
}

std::vector<uint8_t> serializeModel(const Model& model) {
  model.validate("model to serialize");
  return serializeValidated(model);
}

Model deserializeModel(std::span<const uint8_t> bytes, const std::string& sourceName) {
  const ModelFileInfo info = readModelFileInfo(bytes, sourceName);
  Model model;
  for (const auto& sec : info.sections) {
    const SectionCodec* codec = findCodec(sec.tag);
    if (!codec) continue;  // a newer minor version's section, checked and skipped
    const auto payload = bytes.subspan(size_t(sec.offset + kModelSectionHeaderBytes), size_t(sec.payloadBytes));
    ByteReader r(payload, sourceName + ": section '" + sec.tag + "'");
    codec->read(r, model);
    r.expectEnd();
  }
  model.validate(sourceName);
  return model;
}

void saveModel(const Model& model, const std::filesystem::path& path) {
  model.validate(path.string());
  writeFileAtomic(path, serializeValidated(model));
}

Model loadModel(const std::filesystem::path& path) { return deserializeModel(readFileBytes(path), path.string()); }

std::vector<uint8_t> readFileBytes(const std::filesystem::path& path) {
  auto fail = [&](const std::string& problem, int err) {
    throw Error(path.string() + ": " + problem + ": " + std::strerror(err));
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail("cannot open", errno);
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    fail("cannot stat", err);
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    fail("cannot read", EISDIR);
  }
  std::vector<uint8_t> bytes;
  if (S_ISREG(st.st_mode)) bytes.reserve(size_t(st.st_size));
  uint8_t chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      fail("cannot read", err);
    }
    if (n == 0) break;
    bytes.insert(bytes.end(), chunk, chunk + n);
  }
  ::close(fd);
  return bytes;
}

}  // namespace swish
