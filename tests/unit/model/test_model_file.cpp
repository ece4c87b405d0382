// The .swish model file and atomic writes: round trips, truncation, corruption, hostile counts,
// version handling, and that a failed save never damages an existing file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/files/crc32.hpp"
#include "swish/model/model_file.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh, empty folder per test (named after it), removed afterwards.
using swish::test::TempDir;

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

TEST(AtomicWrite, WritesNewFileAndReplacesExistingOne) {
  TempDir dir;
  const fs::path target = dir / "out.txt";
  swish::writeTextFileAtomic(target, "first");
  EXPECT_EQ(readText(target), "first");
  swish::writeTextFileAtomic(target, "second, longer content");
  EXPECT_EQ(readText(target), "second, longer content");
  const std::vector<uint8_t> bytes = {0, 1, 2, 255, 0};
  swish::writeFileAtomic(target, bytes);
  EXPECT_EQ(readText(target), std::string("\0\1\2\xff\0", 5));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicWrite, StaleNumberedOutputsOfAnEarlierRunAreRemovedAndNothingElse) {
  TempDir dir;
  for (const char* n : {"pose_00001_front.png", "pose_00002_front.png", "pose_00002_normal_map.png",
                        "pose_00007_front.png", "pose_notes.txt", "my_front.png", "preview.json"})
    swish::writeTextFileAtomic(dir / n, n);
  fs::create_directory(dir / "pose_00009_front.png");  // not a regular file: left alone
  const std::vector<fs::path> written{dir / "pose_00002_front.png", dir / "pose_00002_normal_map.png",
                                      dir / "preview.json"};
  constexpr std::string_view suffixes[] = {"_front.png", "_normal_map.png"};
  EXPECT_EQ(swish::removeStaleOutputs(dir.path(), "pose_", suffixes, written), 2u);
  std::vector<std::string> left = dir.entries();
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"my_front.png", "pose_00002_front.png", "pose_00002_normal_map.png",
                                            "pose_00009_front.png", "pose_notes.txt", "preview.json"}));
  EXPECT_EQ(swish::removeStaleOutputs(dir / "absent", "pose_", suffixes, written), 0u);  // no folder: nothing to do
}

TEST(AtomicWrite, StreamAndRawWritesKeepTheirOrder) {
  TempDir dir;
  const fs::path target = dir / "mixed.bin";
  swish::AtomicFileWriter w(target);
  w.stream() << "ab";
  const std::vector<uint8_t> mid = {'c', 'd'};
  w.write(mid);
  w.stream() << "ef" << 12;
  EXPECT_FALSE(fs::exists(target)) << "nothing may appear at the target before commit";
  w.commit();
  EXPECT_EQ(readText(target), "abcdef12");
}

TEST(AtomicWrite, LargeStreamedOutputArrivesWhole) {
  TempDir dir;
  const fs::path target = dir / "large.txt";
  std::string expected;
  swish::writeFileAtomicWith(target, [&](std::ostream& os) {
    for (int i = 0; i < 50000; ++i) {
      const std::string line = "line " + std::to_string(i) + "\n";
      os << line;
      expected += line;
    }
  });
  EXPECT_EQ(readText(target), expected);
}

TEST(AtomicWrite, ThrowingWriterLeavesOldFileAndNoTemporary) {
  TempDir dir;
  const fs::path target = dir / "keep.txt";
  swish::writeTextFileAtomic(target, "precious");
  EXPECT_THROW(swish::writeFileAtomicWith(target,
                                          [](std::ostream& os) {
                                            os << "half written";
                                            throw swish::Error("writer gave up");
                                          }),
               swish::Error);
  EXPECT_EQ(readText(target), "precious");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicWrite, UncommittedWriterDiscardsItsTemporary) {
  TempDir dir;
  const fs::path target = dir / "never.txt";
  {
    swish::AtomicFileWriter w(target);
    w.stream() << "abandoned";
    EXPECT_TRUE(fs::exists(w.temporaryPath()));
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicWrite, ErrorsNameThePathAndTheReason) {
  TempDir dir;
  // The parent "folder" is a regular file: creating the temporary fails with ENOTDIR, even as root.
  swish::writeTextFileAtomic(dir / "plain", "x");
  try {
    swish::writeTextFileAtomic(dir / "plain" / "child.txt", "y");
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("child.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Not a directory"), std::string::npos) << msg;
  }
  // Missing folder.
  EXPECT_THROW(swish::writeTextFileAtomic(dir / "missing" / "a.txt", "y"), swish::Error);
  // The target is a folder: refused before anything is written, and the folder survives.
  fs::create_directory(dir / "sub");
  try {
    swish::writeTextFileAtomic(dir / "sub", "y");
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(dir / "sub"));
  EXPECT_EQ(readText(dir / "plain"), "x");
}

// ------------------------------------------------------------------------------------------------
// The .swish format
// ------------------------------------------------------------------------------------------------

namespace {

using swish::Model;
using swish::test::RandomModelSpec;

std::vector<uint8_t> toBytes(std::string_view s) { return {s.begin(), s.end()}; }

// Bitwise comparison of two Eigen objects or vectors: equal shapes and equal bytes (so -0 != +0 and
// NaN payloads matter, unlike operator==).
template <class A>
bool sameBits(const A& a, const A& b) {
  if constexpr (requires { a.rows(); }) {
    // An empty Eigen object's data() is null, which memcmp must not get even for 0 bytes.
    return a.rows() == b.rows() && a.cols() == b.cols() &&
           (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(*a.data()) * size_t(a.size())) == 0);
  } else {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), sizeof(a[0]) * a.size()) == 0);
  }
}

void expectBitwiseEqual(const Model& a, const Model& b) {
  ASSERT_EQ(a.skeleton.joints.size(), b.skeleton.joints.size());
  for (size_t i = 0; i < a.skeleton.joints.size(); ++i) {
    const auto &ja = a.skeleton.joints[i], &jb = b.skeleton.joints[i];
    EXPECT_EQ(ja.name, jb.name);
    EXPECT_EQ(ja.parent, jb.parent);
    EXPECT_TRUE(sameBits(ja.rest.rotation.coeffs(), jb.rest.rotation.coeffs())) << "joint " << i;
    EXPECT_TRUE(sameBits(ja.rest.translation, jb.rest.translation)) << "joint " << i;
  }
  ASSERT_EQ(a.skeleton.inverseBind.size(), b.skeleton.inverseBind.size());
  for (size_t i = 0; i < a.skeleton.inverseBind.size(); ++i)
    EXPECT_TRUE(sameBits(a.skeleton.inverseBind[i], b.skeleton.inverseBind[i])) << "inverse bind " << i;
  EXPECT_EQ(a.inputJoints, b.inputJoints);
  EXPECT_EQ(a.rootGravity, b.rootGravity);
  EXPECT_TRUE(sameBits(a.inputNorm.mean, b.inputNorm.mean));
  EXPECT_TRUE(sameBits(a.inputNorm.scale, b.inputNorm.scale));
  EXPECT_TRUE(sameBits(a.outputNorm.mean, b.outputNorm.mean));
  EXPECT_TRUE(sameBits(a.outputNorm.scale, b.outputNorm.scale));
  ASSERT_EQ(a.mlp.layers.size(), b.mlp.layers.size());
  for (size_t l = 0; l < a.mlp.layers.size(); ++l) {
    EXPECT_TRUE(sameBits(a.mlp.layers[l].weight, b.mlp.layers[l].weight)) << "layer " << l;
    EXPECT_TRUE(sameBits(a.mlp.layers[l].bias, b.mlp.layers[l].bias)) << "layer " << l;
  }
  EXPECT_TRUE(sameBits(a.meshPca.mean, b.meshPca.mean));
  EXPECT_TRUE(sameBits(a.meshPca.basis, b.meshPca.basis));
  const auto &ga = a.gameMesh, &gb = b.gameMesh;
  EXPECT_TRUE(sameBits(ga.positions, gb.positions));
  EXPECT_TRUE(sameBits(ga.normals, gb.normals));
  EXPECT_TRUE(sameBits(ga.tangents, gb.tangents));
  EXPECT_TRUE(sameBits(ga.uvs, gb.uvs));
  EXPECT_TRUE(sameBits(ga.triangles, gb.triangles));
  EXPECT_EQ(ga.skin.influences, gb.skin.influences);
  EXPECT_EQ(ga.skin.joints, gb.skin.joints);
  EXPECT_TRUE(sameBits(ga.skin.weights, gb.skin.weights));
  const auto &da = a.normalMaps, &db = b.normalMaps;
  EXPECT_EQ(da.width, db.width);
  EXPECT_EQ(da.height, db.height);
  EXPECT_TRUE(sameBits(da.keys, db.keys));
  EXPECT_EQ(da.codebookSize, db.codebookSize);
  EXPECT_EQ(da.codebook, db.codebook);
  EXPECT_EQ(da.indices, db.indices);
  EXPECT_EQ(std::memcmp(&a.temporalFilter.timeConstantSeconds, &b.temporalFilter.timeConstantSeconds, 4), 0);
  EXPECT_EQ(std::memcmp(&a.bodyAnchors.margin, &b.bodyAnchors.margin, 4), 0);
  ASSERT_EQ(a.bodyAnchors.anchors.size(), b.bodyAnchors.anchors.size());
  for (size_t v = 0; v < a.bodyAnchors.anchors.size(); ++v) {
    const swish::BodyAnchor &aa = a.bodyAnchors.anchors[v], &ab = b.bodyAnchors.anchors[v];
    EXPECT_TRUE(sameBits(aa.position, ab.position) && sameBits(aa.normal, ab.normal)) << "anchor " << v;
    EXPECT_EQ(std::memcmp(&aa.clearance, &ab.clearance, 4), 0) << "anchor " << v;
    EXPECT_EQ(aa.joints, ab.joints) << "anchor " << v;
    EXPECT_EQ(std::memcmp(aa.weights.data(), ab.weights.data(), sizeof aa.weights), 0) << "anchor " << v;
  }
  const auto &na = a.noveltyGuard, &nb = b.noveltyGuard;
  EXPECT_TRUE(sameBits(na.centres, nb.centres));
  EXPECT_TRUE(sameBits(na.weightMin, nb.weightMin) && sameBits(na.weightMax, nb.weightMax));
  const float fa[4] = {na.unit, na.blendStart, na.blendEnd, na.flagAbove};
  const float fb[4] = {nb.unit, nb.blendStart, nb.blendEnd, nb.flagAbove};
  EXPECT_EQ(std::memcmp(fa, fb, sizeof fa), 0);
  EXPECT_EQ(a.bodyCoverage.bodyTriangles, b.bodyCoverage.bodyTriangles);
  EXPECT_EQ(a.bodyCoverage.covered, b.bodyCoverage.covered);
  EXPECT_EQ(a.metadata, b.metadata);
}

Model smallModel(uint64_t seed = 7) {
  swish::Rng rng(seed);
  RandomModelSpec s;
  s.joints = 3;
  s.inputJoints = 2;
  s.vertices = 6;
  s.influences = 2;
  s.meshComponents = 2;
  s.hiddenLayers = 1;
  s.hiddenWidth = 3;
  s.normalMaps = 2;
  s.codeDims = 2;
  s.mapSize = 4;
  s.codebookSize = 2;
  return swish::test::makeRandomModel(rng, s);
}

// A file taken apart into its sections and put back together, so that tests can change one thing
// and still have correct checksums everywhere else (or deliberately not).
struct RawSection {
  std::string tag;
  std::vector<uint8_t> payload;
};

std::vector<RawSection> splitSections(const std::vector<uint8_t>& file) {
  const auto info = swish::readModelFileInfo(file, "split");
  std::vector<RawSection> out;
  for (const auto& s : info.sections) {
    const auto* p = file.data() + s.offset + swish::kModelSectionHeaderBytes;
    out.push_back({s.tag, std::vector<uint8_t>(p, p + s.payloadBytes)});
  }
  return out;
}

std::vector<uint8_t> assemble(const std::vector<RawSection>& sections, uint16_t major = swish::kModelFileMajorVersion,
                              uint16_t minor = swish::kModelFileMinorVersion) {
  swish::ByteWriter w;
  w.bytes(swish::kModelFileMagic);
  w.u16(major);
  w.u16(minor);
  w.u32(uint32_t(sections.size()));
  size_t total = swish::kModelFileHeaderBytes;
  for (const auto& s : sections) total += swish::kModelSectionHeaderBytes + s.payload.size();
  w.u64(total);
  w.u32(0);
  w.u32(swish::crc32(std::span<const uint8_t>(w.data().data(), 28)));
  for (const auto& s : sections) {
    w.text(s.tag);
    w.u64(s.payload.size());
    w.u32(swish::crc32(s.payload));
    w.bytes(s.payload);
  }
  return w.take();
}

// The sections but those tagged `tags` (a file as an older format version wrote it).
std::vector<RawSection> withoutSections(std::vector<RawSection> sections, std::initializer_list<const char*> tags) {
  for (const char* tag : tags) std::erase_if(sections, [&](const RawSection& s) { return s.tag == tag; });
  return sections;
}

RawSection& sectionOf(std::vector<RawSection>& sections, const std::string& tag) {
  for (auto& s : sections)
    if (s.tag == tag) return s;
  throw std::runtime_error("no section " + tag);
}

void putU32(std::vector<uint8_t>& bytes, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = uint8_t(v >> (8 * i));
}

// The message of the Error that loading `bytes` throws ("" if it loads).
std::string loadError(const std::vector<uint8_t>& bytes, const std::string& name = "model.swish") {
  try {
    swish::deserializeModel(bytes, name);
  } catch (const swish::Error& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "message: " << (haystack)

}  // namespace

TEST(Crc32, MatchesTheStandardCheckValueAndContinues) {
  EXPECT_EQ(swish::crc32(toBytes("123456789")), 0xCBF43926u);
  EXPECT_EQ(swish::crc32(toBytes("")), 0u);
  EXPECT_EQ(swish::crc32(toBytes("The quick brown fox jumps over the lazy dog")), 0x414FA339u);
  // Continuation across every split point (exercises the 4-byte and the byte-wise paths).
  const auto all = toBytes("swish model file checksum, split anywhere");
  const uint32_t whole = swish::crc32(all);
  for (size_t k = 0; k <= all.size(); ++k) {
    const std::span<const uint8_t> s(all);
    EXPECT_EQ(swish::crc32(s.subspan(k), swish::crc32(s.first(k))), whole) << "split at " << k;
  }
}

TEST(ModelFile, RoundTripIsBitwiseExactForManyShapes) {
  SWISH_TEST_SEED_SCOPE(seed, 2024);
  std::vector<std::pair<const char*, RandomModelSpec>> shapes;
  shapes.push_back({"default", {}});
  RandomModelSpec s;
  s.normalMaps = 0;
  shapes.push_back({"no normal maps", s});
  s = {};
  s.vertices = 1;
  shapes.push_back({"one vertex", s});
  s = {};
  s.influences = 8;
  s.joints = 12;
  shapes.push_back({"8 influences", s});
  s = {};
  s.influences = 1;
  s.hiddenLayers = 0;
  shapes.push_back({"1 influence, linear MLP", s});
  s = {};
  s.rootGravity = true;
  shapes.push_back({"gravity in the root's frame after the input joints", s});
  s = {};
  s.bodyAnchors = true;
  shapes.push_back({"body anchors", s});
  s.vertices = 1;
  shapes.push_back({"one vertex with an anchor", s});
  s = {};
  s.joints = 40;
  s.inputJoints = 16;
  s.vertices = 3001;
  s.meshComponents = 30;
  s.hiddenLayers = 5;
  s.hiddenWidth = 32;
  s.normalMaps = 7;
  s.codeDims = 5;
  s.mapSize = 64;
  s.codebookSize = 300;
  shapes.push_back({"large: 3001 vertices, K=30, 5x32 MLP", s});
  swish::Rng rng(seed);
  for (const auto& [name, spec] : shapes) {
    SCOPED_TRACE(name);
    Model m = swish::test::makeRandomModel(rng, spec);
    // Values whose bits a careless writer would lose: negative zero, a subnormal, odd metadata.
    m.meshPca.mean[0] = -0.0f;
    m.inputNorm.mean[0] = 1e-40f;
    m.metadata = std::string("{\"note\":\"caf\xC3\xA9\",\"nul\":\"a") + '\0' + "b\"}";
    m.skeleton.joints[0].name = "Hips \xE2\x9C\x93";
    const auto bytes = swish::serializeModel(m);
    const Model back = swish::deserializeModel(bytes, name);
    expectBitwiseEqual(m, back);
    EXPECT_EQ(swish::serializeModel(back), bytes) << "writing what was read gives the same bytes";
  }
}

TEST(ModelFile, HeaderAndSectionsFollowTheDocumentedLayout) {
  const Model m = smallModel();
  const auto bytes = swish::serializeModel(m);
  ASSERT_GE(bytes.size(), 32u);
  EXPECT_EQ(std::memcmp(bytes.data(), "\x89SWISH\r\n", 8), 0);
  auto u16 = [&](size_t at) { return uint32_t(bytes[at] | bytes[at + 1] << 8); };
  auto u32 = [&](size_t at) { return u16(at) | u16(at + 2) << 16; };
  EXPECT_EQ(u16(8), 1u);
  EXPECT_EQ(u16(10), 5u);
  EXPECT_EQ(u32(12), 17u);
  EXPECT_EQ(uint64_t(u32(16)) | uint64_t(u32(20)) << 32, bytes.size());
  EXPECT_EQ(u32(24), 0u);
  EXPECT_EQ(u32(28), swish::crc32(std::span<const uint8_t>(bytes.data(), 28)));
  // Walk the sections by hand, as a reader written from the comment in model_file.hpp would.
  const char* expectedTags[] = {"SKEL", "INPJ", "NRMI", "NRMO", "MLP ", "MPCA", "MESH", "SKIN", "NMDB",
                                "TFLT", "BPRX", "NOVG", "BCOV", "BANC", "BAN2", "BAN3", "META"};
  size_t at = 32;
  for (const char* tag : expectedTags) {
    ASSERT_LE(at + 16, bytes.size());
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(&bytes[at]), 4), tag);
    const uint64_t size = uint64_t(u32(at + 4)) | uint64_t(u32(at + 8)) << 32;
    ASSERT_LE(at + 16 + size, bytes.size());
    EXPECT_EQ(u32(at + 12), swish::crc32(std::span<const uint8_t>(&bytes[at + 16], size_t(size)))) << tag;
    if (std::string(tag) == "INPJ") {
      EXPECT_EQ(u32(at + 16), m.inputJoints.size());
      EXPECT_EQ(u32(at + 20), m.inputJoints[0]);
    }
    if (std::string(tag) == "MESH") {
      EXPECT_EQ(u32(at + 16), m.gameMesh.vertexCount());
      EXPECT_EQ(u32(at + 20), m.gameMesh.triangleCount());
      EXPECT_EQ(u32(at + 24), 7u) << "normals, tangents and UVs present";
    }
    if (std::string(tag) == "BPRX") {
      EXPECT_EQ(size, 4u);
      EXPECT_EQ(u32(at + 16), 0u) << "the legacy capsule proxy is written empty";
    }
    if (std::string(tag) == "BANC") {
      EXPECT_EQ(size, 8u) << "no anchors: the count and the margin";
      EXPECT_EQ(u32(at + 16), 0u);
    }
    if (std::string(tag) == "BAN2" || std::string(tag) == "BAN3") {
      EXPECT_EQ(size, 4u) << "no second or third anchors: the count";
      EXPECT_EQ(u32(at + 16), 0u);
    }
    if (std::string(tag) == "META") {
      EXPECT_EQ(std::string(reinterpret_cast<const char*>(&bytes[at + 16]), size), m.metadata);
    }
    at += 16 + size;
  }
  EXPECT_EQ(at, bytes.size());
}

TEST(ModelFile, SaveAndLoadThroughTheFileSystem) {
  TempDir dir;
  const Model m = smallModel();
  swish::saveModel(m, dir / "model.swish");
  expectBitwiseEqual(m, swish::loadModel(dir / "model.swish"));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"model.swish"});
}

TEST(ModelFile, MissingOrUnreadableFileIsAnErrorNamingIt) {
  TempDir dir;
  try {
    swish::loadModel(dir / "nope.swish");
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "nope.swish");
    EXPECT_CONTAINS(e.what(), "No such file");
  }
  try {
    swish::loadModel(dir.path());
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "directory");
  }
  swish::writeTextFileAtomic(dir / "empty.swish", "");
  EXPECT_CONTAINS(loadError({}, "empty.swish"), "empty.swish: file is 0 bytes, too short");
  EXPECT_THROW(swish::loadModel(dir / "empty.swish"), swish::Error);
}

TEST(ModelFile, EveryTruncationIsAnError) {
  const auto bytes = swish::serializeModel(smallModel());
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + long(n));
    const std::string msg = loadError(cut);
    EXPECT_FALSE(msg.empty()) << "prefix of " << n << " bytes loaded";
    if (n >= 32) {
      EXPECT_CONTAINS(msg, "(truncated)");
    }
  }
  // One byte too many is caught as well.
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_CONTAINS(loadError(longer), "extra bytes at the end");
}

TEST(ModelFile, EverySingleBitFlipIsDetected) {
  const auto bytes = swish::serializeModel(smallModel());
  for (size_t i = 0; i < bytes.size(); ++i) {
    auto bad = bytes;
    bad[i] ^= uint8_t(1u << (i % 8));
    EXPECT_FALSE(loadError(bad).empty()) << "flip at byte " << i << " went unnoticed";
  }
}

TEST(ModelFile, CorruptPayloadNamesItsSection) {
  const auto bytes = swish::serializeModel(smallModel());
  const auto info = swish::readModelFileInfo(bytes, "x");
  for (const auto& s : info.sections) {
    if (s.payloadBytes == 0) continue;
    for (uint64_t k : {uint64_t(0), s.payloadBytes / 2, s.payloadBytes - 1}) {
      auto bad = bytes;
      bad[size_t(s.offset + 16 + k)] ^= 0x10;
      const std::string msg = loadError(bad);
      EXPECT_CONTAINS(msg, "model.swish: section '" + s.tag + "': checksum mismatch");
    }
  }
}

TEST(ModelFile, WrongMagicAndVersionsAreClearErrors) {
  const auto bytes = swish::serializeModel(smallModel());
  auto bad = bytes;
  bad[1] = 'X';
  EXPECT_CONTAINS(loadError(bad), "model.swish: not a .swish model file (wrong magic bytes)");
  EXPECT_CONTAINS(loadError(toBytes("PK\3\4 this is a zip file, not a model at all")), "wrong magic");

  const auto sections = splitSections(bytes);
  EXPECT_CONTAINS(loadError(assemble(sections, 2, 0)), "format version 2.0 is newer than this swish reads (1.x)");
  EXPECT_CONTAINS(loadError(assemble(sections, 0, 9)), "format version 0.9 is not supported");

  // A newer minor version may add sections: they are skipped and the rest loads.
  auto extended = sections;
  extended.insert(extended.begin() + 3, RawSection{"FUTR", toBytes("something a later swish writes")});
  expectBitwiseEqual(swish::deserializeModel(assemble(extended, 1, 7), "newer.swish"), smallModel());
  const auto info = swish::readModelFileInfo(assemble(extended, 1, 7), "newer.swish");
  EXPECT_FALSE(info.sections[3].known);
  // The same unknown section in a file claiming the current version is corruption.
  EXPECT_CONTAINS(loadError(assemble(extended)), "unknown section 'FUTR' in a version 1.5 file");
}

// Format 1.1 added the capsule proxy (BPRX), legacy since 1.3: a 1.0 file (no BPRX) still loads; a 1.1
// or 1.2 file's capsules are read and dropped (nothing runs on them any more); a 1.1 file without the
// section, or a 1.0 file with it, is refused; a hostile capsule count is refused naming it. A 1.3 file
// writes it empty.
TEST(ModelFile, LegacyCapsuleSectionOfVersion11) {
  swish::Rng rng(11);
  RandomModelSpec spec;
  spec.vertices = 9;
  const Model m = swish::test::makeRandomModel(rng, spec);
  auto sections = splitSections(swish::serializeModel(m));
  // A 1.2 file as 1.2 wrote it: no BANC (nor BAN2), two capsules in BPRX.
  auto v12 = withoutSections(sections, {"BANC", "BAN2", "BAN3"});
  swish::ByteWriter capsules;
  capsules.u32(2);
  for (int c = 0; c < 2; ++c) {
    capsules.u32(uint32_t(c));
    const float ends[7] = {0.f, 1.f, 0.f, 0.f, 1.5f, 0.f, 0.1f};
    capsules.f32s(ends);
  }
  sectionOf(v12, "BPRX").payload = capsules.take();
  expectBitwiseEqual(swish::deserializeModel(assemble(v12, 1, 2), "v12.swish"), m);

  auto without = v12;
  for (const char* tag : {"BPRX", "NOVG", "BCOV"})  // a 1.0 file has none of them
    without.erase(std::find_if(without.begin(), without.end(), [&](const RawSection& s) { return s.tag == tag; }));
  expectBitwiseEqual(swish::deserializeModel(assemble(without, 1, 0), "old.swish"), m);
  EXPECT_CONTAINS(loadError(assemble(without, 1, 2)), "section 'BPRX' is missing");
  EXPECT_CONTAINS(loadError(assemble(v12, 1, 0)), "a section of format 1.1 in a version 1.0 file");

  auto bad = v12;
  putU32(sectionOf(bad, "BPRX").payload, 0, 65);
  EXPECT_CONTAINS(loadError(assemble(bad, 1, 2)), "section 'BPRX': 65 body capsules; at most 64");
  bad = v12;
  putU32(sectionOf(bad, "BPRX").payload, 0, 3);  // one capsule more than the payload holds
  EXPECT_CONTAINS(loadError(assemble(bad, 1, 2)), "body capsule count 3 needs");
}

// Format 1.3 added the body anchors (BANC): round trip; older files load without them; a 1.3 file
// without the section, or a 1.2 file with it, is refused; anchors that do not fit the model are refused
// naming the file, the part and the vertex; hostile counts fail before allocating.
TEST(ModelFile, BodyAnchorSectionOfVersion13) {
  swish::Rng rng(13);
  RandomModelSpec spec;
  spec.vertices = 9;
  spec.bodyAnchors = true;
  const Model m = swish::test::makeRandomModel(rng, spec);
  ASSERT_EQ(m.bodyAnchors.anchors.size(), 9u);
  ASSERT_FALSE(m.bodyAnchors.anchors[3].present());  // (every 7th from 3 has none)
  auto sections = splitSections(swish::serializeModel(m));
  expectBitwiseEqual(swish::deserializeModel(assemble(sections), "new.swish"), m);
  EXPECT_EQ(sectionOf(sections, "BANC").payload.size(), 8u + 9u * (12 + 12 + 4 + 4 + 8 + 16));

  const auto without = withoutSections(sections, {"BANC", "BAN2", "BAN3"});
  Model old = m;
  old.bodyAnchors = {};
  expectBitwiseEqual(swish::deserializeModel(assemble(without, 1, 2), "old.swish"), old);
  EXPECT_CONTAINS(loadError(assemble(without)), "section 'BANC' is missing");
  EXPECT_CONTAINS(loadError(assemble(sections, 1, 2)), "a section of format 1.3 in a version 1.2 file");

  // Payload offsets: count at 0, margin at 4, then the arrays (model_file.hpp).
  const size_t n = 9, positions = 8, normals = positions + 12 * n, radii = normals + 12 * n, clearances = radii + 4 * n,
               joints = clearances + 4 * n, weights = joints + 8 * n;
  auto edited = [&](auto&& edit) {
    auto e = sections;
    edit(sectionOf(e, "BANC").payload);
    return loadError(assemble(e), "anchored.swish");
  };
  auto putF32 = [](std::vector<uint8_t>& p, size_t at, float f) { std::memcpy(&p[at], &f, 4); };
  EXPECT_CONTAINS(edited([&](auto& p) { putU32(p, 0, 8); }), "section 'BANC'");  // fewer than the payload holds
  EXPECT_CONTAINS(edited([&](auto& p) { putU32(p, 0, 0x10000000u); }),
                  "anchored.swish: section 'BANC': body anchor count 268435456 needs");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, 4, 0.5f); }),
                  "anchored.swish: body anchors: margin 0.500000 m is not in [0, 0.05] metres");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, normals + 12 * 1, 2.f); }),
                  "anchored.swish: body anchors: anchor of vertex 1 has a normal that is not of unit length");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, clearances + 4 * 2, 0.01f); }),
                  "body anchors: anchor of vertex 2 has clearance");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, radii + 4 * 7, 0.f); }),
                  "body anchors: anchor of vertex 7 has radius 0.000000 m, not in [0.001, 1]");
  EXPECT_CONTAINS(
      edited([&](auto& p) {
        putF32(p, radii + 4 * 8, 0.002f);
        putF32(p, clearances + 4 * 8, -0.005f);
      }),
      "anchor of vertex 8 has clearance -0.005000 m, not in [-0.2 m, margin] or not above minus its radius");
  EXPECT_CONTAINS(edited([&](auto& p) { p[joints + 8 * 4] = 99; }),
                  "body anchors: anchor of vertex 4 joint 99 >= joint count");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, weights + 16 * 5, 7.f); }),
                  "body anchors: anchor of vertex 5 has weights summing to");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, weights + 16 * 6, -0.5f); }),
                  "body anchors: anchor of vertex 6 has a negative or non-finite weight");
  EXPECT_CONTAINS(edited([&](auto& p) { putF32(p, positions + 12 * 3, 1.f); }),
                  "body anchors: anchor of vertex 3 has no weights (no anchor) but a position");
  EXPECT_CONTAINS(edited([&](auto& p) { p.pop_back(); }), "section 'BANC'");
  Model bad = m;
  bad.bodyAnchors.anchors.pop_back();
  try {
    bad.validate("m");
    ADD_FAILURE() << "anchors for another vertex count were accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: body anchors: 8 anchors for 9 game-mesh vertices");
  }
}

// Sizes too large for an int are refused, not overflowed (fuzz_model_loader found a normal-code
// dimension count of 2^31 - 1 that wrapped the network's expected output size).
TEST(ModelFile, HugeSizesAreRefusedWithoutOverflow) {
  swish::Rng rng(12);
  Model m = swish::test::makeRandomModel(rng);
  m.normalMaps.keys.resize(0, std::numeric_limits<int>::max());
  try {
    m.validate("m");
    ADD_FAILURE() << "a huge normal-code size was accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: mlp: output size");
    EXPECT_CONTAINS(e.what(), "2147483647 normal-code dimensions");
  }
}

// Format 1.4 added the second body anchors (BAN2): round trip; a 1.3 file (no BAN2) loads without
// them; a 1.4 file without the section, or a 1.3 file with it, is refused; second anchors that do not
// fit the model, or that come without first ones, are refused naming them.
TEST(ModelFile, SecondAnchorSectionOfVersion14) {
  swish::Rng rng(14);
  RandomModelSpec spec;
  spec.vertices = 9;
  spec.bodyAnchors = true;
  spec.secondAnchors = true;
  const Model m = swish::test::makeRandomModel(rng, spec);
  ASSERT_EQ(m.bodyAnchors.second.size(), 9u);
  ASSERT_EQ(m.bodyAnchors.slots(), 2u);
  ASSERT_FALSE(m.bodyAnchors.second[1].present());  // (every 5th from 1 has none)
  ASSERT_TRUE(m.bodyAnchors.second[3].present());   // (where the first set has none)
  auto sections = splitSections(swish::serializeModel(m));
  expectBitwiseEqual(swish::deserializeModel(assemble(sections), "new.swish"), m);
  EXPECT_EQ(sectionOf(sections, "BAN2").payload.size(), 4u + 9u * (12 + 12 + 4 + 4 + 8 + 16));

  const auto v13 = withoutSections(sections, {"BAN2", "BAN3"});
  Model old = m;
  old.bodyAnchors.second.clear();
  expectBitwiseEqual(swish::deserializeModel(assemble(v13, 1, 3), "v13.swish"), old);
  EXPECT_EQ(old.bodyAnchors.slots(), 1u);
  EXPECT_CONTAINS(loadError(assemble(v13)), "section 'BAN2' is missing");
  EXPECT_CONTAINS(loadError(assemble(sections, 1, 3)), "a section of format 1.4 in a version 1.3 file");

  // A model without second anchors writes an empty BAN2.
  auto oneSet = splitSections(swish::serializeModel(old));
  EXPECT_EQ(sectionOf(oneSet, "BAN2").payload.size(), 4u);

  const size_t normals = 4 + 12 * 9;
  auto edited = sections;
  std::memcpy(&sectionOf(edited, "BAN2").payload[normals + 12 * 2], "\0\0\0\x40", 4);  // x = 2
  EXPECT_CONTAINS(loadError(assemble(edited), "two.swish"),
                  "two.swish: body anchors: second anchor of vertex 2 has a normal that is not of unit length");
  edited = sections;
  putU32(sectionOf(edited, "BAN2").payload, 0, 0x10000000u);
  EXPECT_CONTAINS(loadError(assemble(edited)), "second body anchor count 268435456 needs");
  Model bad = m;
  bad.bodyAnchors.second.pop_back();
  try {
    bad.validate("m");
    ADD_FAILURE() << "second anchors for another vertex count were accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: body anchors: 8 second anchors for 9 game-mesh vertices");
  }
  bad = m;
  bad.bodyAnchors.anchors.clear();
  try {
    bad.validate("m");
    ADD_FAILURE() << "second anchors without first ones were accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: body anchors: second anchors without first ones");
  }
}

// Format 1.5 added the third (cover) body anchors (BAN3): round trip; a 1.4 file (no BAN3) loads without
// them; a 1.5 file without the section, or a 1.4 file with it, is refused; third anchors that do not fit
// the model, or that come without second ones, are refused naming them.
TEST(ModelFile, ThirdAnchorSectionOfVersion15) {
  swish::Rng rng(15);
  RandomModelSpec spec;
  spec.vertices = 9;
  spec.bodyAnchors = true;
  spec.secondAnchors = true;
  spec.thirdAnchors = true;
  const Model m = swish::test::makeRandomModel(rng, spec);
  ASSERT_EQ(m.bodyAnchors.third.size(), 9u);
  ASSERT_EQ(m.bodyAnchors.slots(), 3u);
  ASSERT_FALSE(m.bodyAnchors.third[2].present());  // (every 3rd from 2 has none)
  ASSERT_TRUE(m.bodyAnchors.third[0].present());
  auto sections = splitSections(swish::serializeModel(m));
  expectBitwiseEqual(swish::deserializeModel(assemble(sections), "new.swish"), m);
  EXPECT_EQ(sectionOf(sections, "BAN3").payload.size(), 4u + 9u * (12 + 12 + 4 + 4 + 8 + 16));

  const auto v14 = withoutSections(sections, {"BAN3"});
  Model old = m;
  old.bodyAnchors.third.clear();
  expectBitwiseEqual(swish::deserializeModel(assemble(v14, 1, 4), "v14.swish"), old);
  EXPECT_EQ(old.bodyAnchors.slots(), 2u);
  EXPECT_CONTAINS(loadError(assemble(v14)), "section 'BAN3' is missing");
  EXPECT_CONTAINS(loadError(assemble(sections, 1, 4)), "a section of format 1.5 in a version 1.4 file");
  auto twoSets = splitSections(swish::serializeModel(old));
  EXPECT_EQ(sectionOf(twoSets, "BAN3").payload.size(), 4u);

  auto edited = sections;
  const size_t radii = 4 + 24 * 9;
  std::memcpy(&sectionOf(edited, "BAN3").payload[radii + 4 * 3], "\0\0\0\0", 4);  // radius 0
  EXPECT_CONTAINS(loadError(assemble(edited), "three.swish"),
                  "three.swish: body anchors: third anchor of vertex 3 has");
  Model bad = m;
  bad.bodyAnchors.third.pop_back();
  try {
    bad.validate("m");
    ADD_FAILURE() << "third anchors for another vertex count were accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: body anchors: 8 third anchors for 9 game-mesh vertices");
  }
  bad = m;
  bad.bodyAnchors.second.clear();
  try {
    bad.validate("m");
    ADD_FAILURE() << "third anchors without second ones were accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "m: body anchors: third anchors without second ones");
  }
}

// Format 1.2 added the novelty guard: older files load without one; a 1.2 file without it, or a 1.1
// file with it, is refused; a guard that does not fit the model is refused naming the part.
TEST(ModelFile, NoveltyGuardSectionOfVersion12) {
  swish::Rng rng(12);
  RandomModelSpec spec;
  spec.vertices = 9;
  spec.noveltyCentres = 5;
  const Model m = swish::test::makeRandomModel(rng, spec);
  ASSERT_FALSE(m.noveltyGuard.empty());
  auto sections = splitSections(swish::serializeModel(m));
  expectBitwiseEqual(swish::deserializeModel(assemble(sections), "new.swish"), m);

  auto without = sections;
  for (const char* tag : {"NOVG", "BCOV", "BANC", "BAN2", "BAN3"})
    without.erase(std::find_if(without.begin(), without.end(), [&](const RawSection& s) { return s.tag == tag; }));
  Model old = m;
  old.noveltyGuard = {};
  old.bodyCoverage = {};
  expectBitwiseEqual(swish::deserializeModel(assemble(without, 1, 1), "old.swish"), old);
  EXPECT_CONTAINS(loadError(assemble(without)), "section 'NOVG' is missing");
  EXPECT_CONTAINS(loadError(assemble(sections, 1, 1)), "a section of format 1.2 in a version 1.1 file");

  Model bad = m;
  bad.noveltyGuard.centres.conservativeResize(Eigen::NoChange, m.thetaSize() - 1);
  EXPECT_THROW(bad.validate(), swish::Error);
  bad = m;
  bad.noveltyGuard.weightMax[0] = bad.noveltyGuard.weightMin[0] - 1.f;
  try {
    bad.validate("m");
    ADD_FAILURE() << "an empty weight range was accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "novelty guard: weight range 0 is empty or not finite");
  }
  auto hostile = sections;
  putU32(sectionOf(hostile, "NOVG").payload, 0, 0x10000000u);
  EXPECT_CONTAINS(loadError(assemble(hostile)), "novelty centre");

  // Body coverage, also new in 1.2: round trip, then a list that is not ascending below the count.
  Model covered = m;
  covered.bodyCoverage = {10, {1, 4, 9}};
  const auto coveredSections = splitSections(swish::serializeModel(covered));
  expectBitwiseEqual(swish::deserializeModel(assemble(coveredSections), "covered.swish"), covered);
  covered.bodyCoverage.covered = {1, 10};
  EXPECT_THROW(covered.validate(), swish::Error);
  covered.bodyCoverage.covered = {4, 1};
  try {
    covered.validate("m");
    ADD_FAILURE() << "a descending list was accepted";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "body coverage: triangle 1 (entry 1) is not ascending");
  }
}

TEST(ModelFile, HostileCountsFailBeforeAllocating) {
  const auto sections = splitSections(swish::serializeModel(smallModel()));
  struct Case {
    const char* tag;
    size_t offset;
    uint32_t value;
    const char* message;
  };
  const Case cases[] = {
      {"MESH", 4, 0xFFFFFFFFu,
       "model.swish: section 'MESH': triangle count 4294967295 needs 51539607540 bytes but the section has"},
      {"MESH", 0, 0xFFFFFFFFu, "section 'MESH': vertex count 4294967295 needs"},
      {"SKEL", 0, 0xFFFFFFFFu, "section 'SKEL': joint count 4294967295 needs"},
      {"SKEL", 4, 0x7FFFFFFFu, "section 'SKEL': joint name byte count 2147483647 needs"},
      {"INPJ", 0, 0xFFFFFFFFu, "section 'INPJ': input joint count 4294967295 needs 17179869180 bytes"},
      {"NRMI", 0, 0x40000000u, "section 'NRMI': normalisation value count 1073741824 needs"},
      {"MLP ", 0, 0xFFFFFFFFu, "section 'MLP ': layer count 4294967295 needs"},
      {"MLP ", 4, 0xFFFFFFFFu, "section 'MLP ': layer weight count"},
      {"MPCA", 4, 0xFFFFFFFFu, "section 'MPCA': mesh pca basis value count"},
      {"SKIN", 4, 0xFFFFFFFFu, "section 'SKIN': skin entry count"},
      {"SKIN", 0, 9u, "section 'SKIN': influence count 9 outside 0..8"},
      {"NMDB", 16, 0xFFFFFFFFu, "section 'NMDB': codebook byte count 137438953440 needs"},
      {"NMDB", 8, 0xFFFFFFFFu, "section 'NMDB': key value count"},
      {"NMDB", 0, 0xFFFFFFFCu, "section 'NMDB': block index count"},
      {"NMDB", 0, 6u, "section 'NMDB': map size 6x4 is not a multiple of 4"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::string(c.tag) + " at " + std::to_string(c.offset));
    auto edited = sections;
    putU32(sectionOf(edited, c.tag).payload, c.offset, c.value);
    EXPECT_CONTAINS(loadError(assemble(edited)), c.message);
  }
  // The section count itself.
  auto file = assemble(sections);
  putU32(file, 12, 0xFFFFFFFFu);
  putU32(file, 28, swish::crc32(std::span<const uint8_t>(file.data(), 28)));
  EXPECT_CONTAINS(loadError(file), "model.swish: section count 4294967295 needs 68719476720 bytes but the file has");
}

TEST(ModelFile, StructuralProblemsAreNamed) {
  const auto sections = splitSections(swish::serializeModel(smallModel()));
  {  // an out-of-range triangle index: parsed fine, refused by validation with the file's name
    auto e = sections;
    auto& mesh = sectionOf(e, "MESH").payload;
    putU32(mesh, mesh.size() - 4, 1000);
    const std::string msg = loadError(assemble(e));
    EXPECT_CONTAINS(msg, "model.swish");
    EXPECT_CONTAINS(msg, "uses vertex 1000");
  }
  {  // an input joint outside the skeleton
    auto e = sections;
    putU32(sectionOf(e, "INPJ").payload, 4, 99);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: input joints: index 99 >= joint count 3");
  }
  {  // trailing bytes inside a section
    auto e = sections;
    sectionOf(e, "TFLT").payload.push_back(0);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: section 'TFLT': 1 unexpected bytes after the last field");
  }
  {  // a missing section
    auto e = sections;
    e.erase(e.begin() + 6);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: section 'MESH' is missing");
  }
  {  // a repeated section
    auto e = sections;
    e.push_back(e[1]);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: section 'INPJ' appears twice");
  }
  {  // sections in another order are fine
    auto e = sections;
    std::reverse(e.begin(), e.end());
    expectBitwiseEqual(swish::deserializeModel(assemble(e), "reversed"), smallModel());
  }
  {  // a NaN rest normal: parsed, then refused by validation
    auto e = sections;
    auto& mesh = sectionOf(e, "MESH").payload;
    const size_t firstNormal = 12 + 12 * smallModel().gameMesh.vertexCount();
    putU32(mesh, firstNormal, 0x7FC00000u);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: game mesh: has non-finite rest normals or tangents");
  }
  {  // a NaN MLP weight
    auto e = sections;
    putU32(sectionOf(e, "MLP ").payload, 12, 0x7FC00000u);
    EXPECT_CONTAINS(loadError(assemble(e)), "model.swish: mlp: layer 0 has non-finite values");
  }
  {  // unknown attribute flags in the mesh
    auto e = sections;
    putU32(sectionOf(e, "MESH").payload, 8, 0x17);
    EXPECT_CONTAINS(loadError(assemble(e)), "section 'MESH': unknown attribute flags 23");
  }
}

TEST(ModelFile, FailedSaveLeavesTheExistingFileIntact) {
  TempDir dir;
  const fs::path path = dir / "model.swish";
  const Model good = smallModel(1);
  swish::saveModel(good, path);
  const std::string before = readText(path);

  Model invalid = smallModel(2);
  invalid.inputJoints.push_back(77);  // refers to no joint
  try {
    swish::saveModel(invalid, path);
    FAIL() << "an invalid model was saved";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(e.what(), "model.swish");
  }
  EXPECT_EQ(readText(path), before);
  EXPECT_THROW(swish::serializeModel(invalid), swish::Error);

  // Saving over a folder fails without touching the folder or the other file.
  fs::create_directory(dir / "folder.swish");
  EXPECT_THROW(swish::saveModel(good, dir / "folder.swish"), swish::Error);
  EXPECT_TRUE(fs::is_directory(dir / "folder.swish"));
  // Nothing half-written is left beside the model.
  auto entries = dir.entries();
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"folder.swish", "model.swish"}));
  expectBitwiseEqual(swish::loadModel(path), good);
}

// Model::rootGravity rides in INPJ as a last entry 0xFFFFFFFF (no new section): a file without it reads
// as before, one with it loses the entry into the flag, and a reader that predates it would see an input
// joint beyond the skeleton (Model::validate's message, checked here by placing the entry first).
TEST(ModelFile, RootGravityIsALastInputEntry) {
  swish::Rng rng(77);
  RandomModelSpec s;
  s.rootGravity = true;
  Model m = swish::test::makeRandomModel(rng, s);
  EXPECT_EQ(m.thetaSize(), 6 * int(m.inputJoints.size()) + 3);
  auto sections = splitSections(swish::serializeModel(m));
  const auto& inpj = sectionOf(sections, "INPJ").payload;
  ASSERT_EQ(inpj.size(), 4u * (1 + m.inputJoints.size() + 1));
  auto u32At = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, inpj.data() + at, 4);
    return v;
  };
  EXPECT_EQ(u32At(0), m.inputJoints.size() + 1);
  EXPECT_EQ(u32At(4 * (1 + m.inputJoints.size())), 0xFFFFFFFFu);
  EXPECT_TRUE(swish::deserializeModel(assemble(sections), "gravity").rootGravity);

  // The entry anywhere but last is an input joint beyond the skeleton, and so is a network without room.
  auto moved = sections;
  auto& p = sectionOf(moved, "INPJ").payload;
  std::swap_ranges(p.begin() + 4, p.begin() + 8, p.begin() + 4 + 4 * std::ptrdiff_t(m.inputJoints.size()));
  EXPECT_CONTAINS(loadError(assemble(moved)), "input joints: index 4294967295 >= joint count");
  m.rootGravity = false;  // the network still reads 3 more values
  try {
    m.validate("model");
    ADD_FAILURE() << "a network reading 3 values more than Theta validated";
  } catch (const swish::Error& e) {
    EXPECT_CONTAINS(std::string(e.what()), "input size");
  }
}
