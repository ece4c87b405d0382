#pragma once
// The .swish model file: everything the run time needs for one garment, in one checked binary file.
//
// ==================================== Layout, format version 1.5 ====================================
// All integers are unsigned little-endian unless marked i32 (two's complement). f32 is IEEE-754
// binary32, little-endian, bit pattern kept exactly. There is no padding or alignment anywhere: fields
// follow each other byte after byte. Matrices are column-major (Eigen's order) unless said otherwise.
//
// File header, 32 bytes:
//   0   u8[8]  magic: 0x89 'S' 'W' 'I' 'S' 'H' 0x0D 0x0A  (0x89 and CR LF catch text-mode mangling)
//   8   u16    major version = 1. A reader refuses a larger major version.
//   10  u16    minor version = 5. Minor versions only ADD sections; a reader skips tags it does not
//              know when the file's minor version is newer than its own, and refuses them otherwise.
//   12  u32    section count
//   16  u64    total file size in bytes, header included (catches truncation before anything else)
//   24  u32    reserved, 0
//   28  u32    CRC-32 (zlib's, see crc32.hpp) of bytes 0..27
// Then `section count` sections back to back, ending exactly at the end of the file:
//   0   u8[4]  tag, ASCII
//   4   u64    payload size in bytes
//   12  u32    CRC-32 of the payload
//   16  u8[payload size] payload; every payload must be read to its last byte (trailing bytes = error)
//
// Sections of version 1.0: each exactly once, all required, any order (the writer uses this one and
// puts BPRX, NOVG, BCOV, BANC, BAN2 and BAN3 before META).
//   "SKEL" skeleton. u32 J joints, then per joint: u32 name length L, u8[L] UTF-8 name, i32 parent
//          (-1 for a root, else an earlier joint), f32[4] rest rotation quaternion x y z w, f32[3] rest
//          translation. Then u32 B (0 or J) inverse bind matrices, each f32[16] column-major 4x4.
//   "INPJ" input joints: u32 n, u32[n] skeleton joint indices. Theta = their 6D rotations in order. A
//          last index 0xFFFFFFFF is no joint: Theta then ends with the gravity direction in the root
//          joint's frame, 3 values (Model::rootGravity; readers from before it refuse such a file,
//          naming an input joint beyond the skeleton).
//   "NRMI" input normalisation over Theta:   u32 n, f32[n] mean, f32[n] scale. x' = (x - mean) / scale.
//   "NRMO" output normalisation over Lambda: u32 n, f32[n] mean, f32[n] scale.
//   "MLP " u32 layer count; per layer: u32 out, u32 in, f32[out*in] weight (column-major, out x in),
//          f32[out] bias. SELU follows every layer but the last.
//   "MPCA" mesh PCA in pre-skinning space: u32 R (= 3 x vertex count), u32 K components, f32[R] mean,
//          f32[R*K] basis column-major (component after component). Row 3v+a is vertex v, axis a.
//   "MESH" game mesh: u32 N vertices, u32 T triangles, u32 attribute flags (bit 0 normals, bit 1
//          tangents, bit 2 UVs; other bits must be 0), f32[3N] positions (x y z per vertex), then
//          if flagged f32[3N] rest normals, f32[4N] rest tangents (x y z, w = bitangent sign),
//          f32[2N] UVs; then u32[3T] triangle vertex indices.
//   "SKIN" skin weights: u32 I influences per vertex (0..8; 0 means no skin, and then N is 0), u32 N
//          vertices, u16[N*I] joint indices (vertex after vertex), f32[N*I] weights.
//   "NMDB" normal-map database: u32 width, u32 height (multiples of 4; both 0 with no maps), u32 M
//          maps, u32 C code dimensions, u32 E codebook entries, f32[M*C] keys (map after map),
//          i8[E*32] codebook (entry after entry; 16 texels of a 4x4 block row-major, X then Y,
//          snorm8), u16[M * (width/4) * (height/4)] block indices (map after map, blocks row-major).
//          M = 0 is a model without normal maps. Decoding: see NormalMapDatabase in model.hpp.
//   "TFLT" temporal filter: f32 time constant in seconds (0 = no filtering).
//   "META" free-form metadata, UTF-8 JSON text, the whole payload, no terminator.
// Added in version 1.1 (required in 1.1 files; a 1.0 file has none and loads with an empty proxy; a
// 1.0 file that holds one is refused):
//   "BPRX" body proxy of the first run-time push-out: u32 C capsules (0..64), then per capsule u32
//          joint, f32[3] end a, f32[3] end b (rest character space), f32 radius (metres). LEGACY since
//          1.3: the capsules were replaced by the body anchors (BANC); a 1.3 writer still writes the
//          section with C = 0 (so that 1.1 and 1.2 readers, which require it, load the file without a
//          push-out), and a reader checks the capsules' size and drops them.
// Added in version 1.2 (required in 1.2 files; older files load with an empty guard):
//   "NOVG" novelty guard: u32 C centres, u32 D inputs (C = 0: none; else D = Theta's size), f32[C*D]
//          centres (centre after centre), f32 unit, u32 K weight ranges (0 or the mesh components),
//          f32[K] minimum, f32[K] maximum, f32 blend start, f32 blend end, f32 flag threshold. See
//          NoveltyGuard.
//   "BCOV" body coverage: u32 body triangle count B, u32 n, u32[n] covered triangle indices
//          (ascending, < B). See BodyCoverage.
// Added in version 1.3 (required in 1.3 files; older files load without anchors, i.e. no push-out):
//   "BANC" body anchors of the run-time push-out: u32 A (0, or the game mesh's vertex count N), f32
//          margin (metres, 0..0.05), then f32[3A] rest positions, f32[3A] rest normals (unit),
//          f32[A] ball radii (metres, 0.001..1), f32[A] clearances (metres, -0.2..margin, above minus
//          the radius), u16[4A] joints, f32[4A] weights (4 influences per anchor, each vertex's after
//          the previous one's). A vertex without an anchor has all of its values 0. See BodyAnchor.
// Added in version 1.4 (required in 1.4 files; older files load without second anchors):
//   "BAN2" second body anchors (BodyAnchors::second, applied after BANC's): u32 A2 (0, or N when
//          BANC's A is N), then the same arrays as BANC's after its margin, for A2 anchors.
// Added in version 1.5 (required in 1.5 files; older files load without third anchors):
//   "BAN3" third (cover) body anchors (BodyAnchors::third, applied after BAN2's): u32 A3 (0, or N when
//          BAN2's A2 is N), then the same arrays as BANC's after its margin, for A3 anchors.
// After parsing, Model::validate checks every index and size the run time relies on.
// =====================================================================================================
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "swish/model/model.hpp"

namespace swish {

constexpr uint16_t kModelFileMajorVersion = 1;
constexpr uint16_t kModelFileMinorVersion = 5;
constexpr std::array<uint8_t, 8> kModelFileMagic = {0x89, 'S', 'W', 'I', 'S', 'H', 0x0D, 0x0A};
constexpr size_t kModelFileHeaderBytes = 32;
constexpr size_t kModelSectionHeaderBytes = 16;

// The model as bytes of the current format version. Validates the model first (Error if invalid).
std::vector<uint8_t> serializeModel(const Model& model);
// Parses and validates; `sourceName` (usually the file name) starts every error message.
Model deserializeModel(std::span<const uint8_t> bytes, const std::string& sourceName);

// Validates, serializes and writes atomically: on failure the file at `path` is left as it was.
void saveModel(const Model& model, const std::filesystem::path& path);
// Reads and deserializes; a missing or unreadable file is an Error naming it.
Model loadModel(const std::filesystem::path& path);

// The container level of a file, for tools (`swish inspect`): header and sections with their sizes,
// after checking the magic, version, sizes and every checksum (Error otherwise), without parsing the
// payloads.
struct ModelFileSection {
  std::string tag;      // 4 characters
  uint64_t offset = 0;  // of the section header from the start of the file
  uint64_t payloadBytes = 0;
  uint32_t crc = 0;
  bool known = true;  // false: a section of a newer minor version that this reader skips
};
struct ModelFileInfo {
  uint16_t majorVersion = 0, minorVersion = 0;
  uint64_t totalBytes = 0;
  std::vector<ModelFileSection> sections;
};
ModelFileInfo readModelFileInfo(std::span<const uint8_t> bytes, const std::string& sourceName);

// The whole file as bytes (Error naming the file when it cannot be read).
std::vector<uint8_t> readFileBytes(const std::filesystem::path& path);

}  // namespace swish
