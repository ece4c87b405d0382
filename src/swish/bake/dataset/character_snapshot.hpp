#pragma once
// A character stored inside a dataset folder (character.bin), so that part 2 of the bake reads a
// dataset without re-importing the source files, and a resumed bake can check it is adding poses for
// the same character. Binary, little-endian (ByteWriter/ByteReader):
//   "SWCHAR01" | u32 version (1) | name | skeleton | body | garment | u8 has simulation mesh | [mesh] |
//   u32 CRC-32 of everything before.
//   string   = u32 length | bytes
//   skeleton = u32 joints | per joint: string name, i32 parent, f32 rest quaternion (w, x, y, z),
//              f32 rest translation (3) | u32 inverse-bind count | f32 matrices (16 each, column-major)
//   mesh     = u32 vertices | u32 triangles | u8 flags (1 normals, 2 tangents, 4 uvs) |
//              f32 positions 3N | [normals 3N] | [tangents 4N] | [uvs 2N] | u32 indices 3T |
//              i32 influences | u32 skinned vertex count (N or 0) | u16 joints | f32 weights
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::bake {

std::vector<uint8_t> encodeCharacterSnapshot(const Character& character);
// Validates everything (skeleton order, mesh indices, skin weights against the joint count); throws
// Error starting with `what` (the file name).
Character decodeCharacterSnapshot(std::span<const uint8_t> bytes, const std::string& what);

}  // namespace swish::bake
