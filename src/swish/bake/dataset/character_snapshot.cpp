#include "swish/bake/dataset/character_snapshot.hpp"

#include <cstring>

#include "swish/core/error.hpp"
#include "swish/files/byte_reader.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/files/crc32.hpp"

namespace swish::bake {
namespace {

constexpr char kMagic[8] = {'S', 'W', 'C', 'H', 'A', 'R', '0', '1'};
constexpr uint32_t kVersion = 1;

void putString(ByteWriter& w, const std::string& s) {
  w.u32(uint32_t(s.size()));
  w.text(s);
}
std::string getString(ByteReader& r, const char* what) {
  const size_t n = r.checkCount(r.u32(what), 1, what);
  const auto v = r.view(n, what);
  return std::string(v.begin(), v.end());
}

void putMesh(ByteWriter& w, const Mesh& m) {
  const size_t n = m.vertexCount();
  w.u32(uint32_t(n));
  w.u32(uint32_t(m.triangleCount()));
  const uint8_t flags =
      uint8_t((size_t(m.normals.rows()) == n && n ? 1 : 0) | (size_t(m.tangents.rows()) == n && n ? 2 : 0) |
              (size_t(m.uvs.rows()) == n && n ? 4 : 0));
  w.u8(flags);
  w.f32s({m.positions.data(), size_t(m.positions.size())});
  if (flags & 1) w.f32s({m.normals.data(), size_t(m.normals.size())});
  if (flags & 2) w.f32s({m.tangents.data(), size_t(m.tangents.size())});
  if (flags & 4) w.f32s({m.uvs.data(), size_t(m.uvs.size())});
  w.u32s({m.triangles.data(), size_t(m.triangles.size())});
  w.i32(m.skin.influences);
  const size_t skinned = m.skin.vertexCount();
  w.u32(uint32_t(skinned));
  w.u16s(m.skin.joints);
  w.f32s(m.skin.weights);
}

Mesh getMesh(ByteReader& r) {
  Mesh m;
  const uint32_t n = r.u32("vertex"), t = r.u32("triangle");
  const uint8_t flags = r.u8("mesh flags");
  if (flags & ~7u) r.fail("unknown mesh flags " + std::to_string(flags));
  r.checkCount(r.multiply(n, 12, "positions"), 1, "position");
  m.positions.resize(n, 3);
  r.f32s(m.positions.data(), size_t(n) * 3, "positions");
  if (flags & 1) {
    r.checkCount(r.multiply(n, 12, "normals"), 1, "normal");
    m.normals.resize(n, 3);
    r.f32s(m.normals.data(), size_t(n) * 3, "normals");
  }
  if (flags & 2) {
    r.checkCount(r.multiply(n, 16, "tangents"), 1, "tangent");
    m.tangents.resize(n, 4);
    r.f32s(m.tangents.data(), size_t(n) * 4, "tangents");
  }
  if (flags & 4) {
    r.checkCount(r.multiply(n, 8, "uvs"), 1, "uv");
    m.uvs.resize(n, 2);
    r.f32s(m.uvs.data(), size_t(n) * 2, "uvs");
  }
  r.checkCount(r.multiply(t, 12, "triangles"), 1, "triangle index");
  m.triangles.resize(t, 3);
  r.u32s(m.triangles.data(), size_t(t) * 3, "triangles");
  m.skin.influences = r.i32("influences");
  const uint32_t skinned = r.u32("skinned vertex");
  if (m.skin.influences < 0 || m.skin.influences > kMaxInfluences)
    r.fail("skin influences " + std::to_string(m.skin.influences) + " outside 0.." + std::to_string(kMaxInfluences));
  if (skinned != 0 && skinned != n)
    r.fail("skin covers " + std::to_string(skinned) + " of " + std::to_string(n) + " vertices");
  const uint64_t entries = r.multiply(skinned, uint64_t(m.skin.influences), "skin");
  r.checkCount(entries, 6, "skin entry");
  m.skin.joints.resize(size_t(entries));
  m.skin.weights.resize(size_t(entries));
  r.u16s(m.skin.joints.data(), size_t(entries), "skin joints");
  r.f32s(m.skin.weights.data(), size_t(entries), "skin weights");
  return m;
}

}  // namespace

std::vector<uint8_t> encodeCharacterSnapshot(const Character& c) {
  ByteWriter w;
  w.bytes({reinterpret_cast<const uint8_t*>(kMagic), 8});
  w.u32(kVersion);
  putString(w, c.name);
  w.u32(uint32_t(c.skeleton.joints.size()));
  for (const Joint& j : c.skeleton.joints) {
    putString(w, j.name);
    w.i32(j.parent);
    const Quatf& q = j.rest.rotation;
    w.f32(q.w()), w.f32(q.x()), w.f32(q.y()), w.f32(q.z());
    w.f32(j.rest.translation.x()), w.f32(j.rest.translation.y()), w.f32(j.rest.translation.z());
  }
  w.u32(uint32_t(c.skeleton.inverseBind.size()));
  for (const Mat4f& m : c.skeleton.inverseBind) w.f32s({m.data(), 16});
  putMesh(w, c.body);
  putMesh(w, c.garment);
  w.u8(c.simulationMesh ? 1 : 0);
  if (c.simulationMesh) putMesh(w, *c.simulationMesh);
  w.u32(crc32(w.data()));
  return w.take();
}

Character decodeCharacterSnapshot(std::span<const uint8_t> bytes, const std::string& what) {
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw Error(what + ": not a swish character snapshot (bad magic)");
  const uint32_t stored = uint32_t(bytes[bytes.size() - 4]) | uint32_t(bytes[bytes.size() - 3]) << 8 |
                          uint32_t(bytes[bytes.size() - 2]) << 16 | uint32_t(bytes[bytes.size() - 1]) << 24;
  if (crc32(bytes.first(bytes.size() - 4)) != stored) throw Error(what + ": checksum mismatch (corrupt file)");
  ByteReader r(bytes.first(bytes.size() - 4), what, "file");
  r.skip(8, "magic");
  const uint32_t version = r.u32("version");
  if (version != kVersion)
    r.fail("version " + std::to_string(version) + " (this build reads " + std::to_string(kVersion) + ")");
  Character c;
  c.name = getString(r, "name");
  const size_t joints = r.checkCount(r.u32("joint"), 40, "joint");
  c.skeleton.joints.resize(joints);
  for (Joint& j : c.skeleton.joints) {
    j.name = getString(r, "joint name");
    j.parent = r.i32("parent");
    const float qw = r.f32("rotation"), qx = r.f32("rotation"), qy = r.f32("rotation"), qz = r.f32("rotation");
    j.rest.rotation = Quatf(qw, qx, qy, qz);
    j.rest.translation.x() = r.f32("translation");
    j.rest.translation.y() = r.f32("translation");
    j.rest.translation.z() = r.f32("translation");
  }
  const size_t ib = r.checkCount(r.u32("inverse bind"), 64, "inverse bind");
  c.skeleton.inverseBind.resize(ib);
  for (Mat4f& m : c.skeleton.inverseBind) r.f32s(m.data(), 16, "inverse bind");
  c.body = getMesh(r);
  c.garment = getMesh(r);
  if (r.u8("simulation mesh flag")) c.simulationMesh = getMesh(r);
  r.expectEnd();
  c.skeleton.validate(what + ": skeleton");
  c.body.validate(what + ": body", c.skeleton.size());
  c.garment.validate(what + ": garment", c.skeleton.size());
  if (c.simulationMesh) c.simulationMesh->validate(what + ": simulation mesh", c.skeleton.size());
  return c;
}

}  // namespace swish::bake
