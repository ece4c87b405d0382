#include "swish/replay/gltf_frame_writer.hpp"

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "swish/core/error.hpp"
#include "swish/model/atomic_write.hpp"

namespace swish::replay {

namespace {

using nlohmann::json;

std::string base64(const std::vector<uint8_t>& b) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((b.size() + 2) / 3 * 4);
  for (size_t i = 0; i < b.size(); i += 3) {
    const uint32_t v = uint32_t(b[i]) << 16 | (i + 1 < b.size() ? uint32_t(b[i + 1]) << 8 : 0) | (i + 2 < b.size() ? b[i + 2] : 0);
    o += t[v >> 18 & 63];
    o += t[v >> 12 & 63];
    o += i + 1 < b.size() ? t[v >> 6 & 63] : '=';
    o += i + 2 < b.size() ? t[v & 63] : '=';
  }
  return o;
}

}  // namespace

void writeGltfFrame(const std::filesystem::path& file, const std::vector<GltfCharacterMesh>& chars) {
  std::vector<uint8_t> bin;
  json j{{"asset", {{"version", "2.0"}, {"generator", "swish replay"}}}, {"scene", 0}};
  json nodes = json::array(), meshes = json::array(), views = json::array(), accessors = json::array();
  auto addView = [&](const void* data, size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t off = bin.size();
    bin.resize(off + bytes);
    std::memcpy(bin.data() + off, data, bytes);
    views.push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes}, {"target", target}});
    return int(views.size() - 1);
  };
  auto addFloatAccessor = [&](const float* data, size_t rows, int cols, bool minMax) {
    json a{{"bufferView", addView(data, rows * size_t(cols) * 4, 34962)}, {"componentType", 5126}, {"count", rows},
           {"type", cols == 2 ? "VEC2" : "VEC3"}};
    if (minMax && rows > 0) {
      std::vector<float> lo(size_t(cols), INFINITY), hi(size_t(cols), -INFINITY);
      for (size_t r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) lo[size_t(c)] = std::min(lo[size_t(c)], data[r * size_t(cols) + size_t(c)]),
                                        hi[size_t(c)] = std::max(hi[size_t(c)], data[r * size_t(cols) + size_t(c)]);
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return int(accessors.size() - 1);
  };
  for (const auto& c : chars) {
    if (!c.positions || !c.triangles) throw Error(file.string() + ": character '" + c.name + "' has no mesh");
    if (!c.positions->allFinite()) throw Error(file.string() + ": character '" + c.name + "' has non-finite positions");
    json attrs{{"POSITION", addFloatAccessor(c.positions->data(), size_t(c.positions->rows()), 3, true)}};
    if (c.normals && c.normals->rows() == c.positions->rows())
      attrs["NORMAL"] = addFloatAccessor(c.normals->data(), size_t(c.normals->rows()), 3, false);
    if (c.uvs && c.uvs->rows() == c.positions->rows())
      attrs["TEXCOORD_0"] = addFloatAccessor(c.uvs->data(), size_t(c.uvs->rows()), 2, false);
    accessors.push_back({{"bufferView", addView(c.triangles->data(), size_t(c.triangles->size()) * 4, 34963)},
                         {"componentType", 5125}, {"count", c.triangles->size()}, {"type", "SCALAR"}});
    meshes.push_back({{"name", c.name}, {"primitives", {{{"attributes", attrs}, {"indices", int(accessors.size() - 1)}}}}});
    const double half = c.placement.yawDegrees * M_PI / 360.0;
    const auto& t = c.placement.translation;
    nodes.push_back({{"name", c.name}, {"mesh", int(meshes.size() - 1)}, {"translation", {t.x(), t.y(), t.z()}},
                     {"rotation", {0.0, std::sin(half), 0.0, std::cos(half)}}});
  }
  json sceneNodes = json::array();
  for (size_t i = 0; i < nodes.size(); ++i) sceneNodes.push_back(i);
  j["scenes"] = {{{"nodes", sceneNodes}}};
  j["nodes"] = nodes;
  j["meshes"] = meshes;
  j["accessors"] = accessors;
  j["bufferViews"] = views;
  j["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
  writeTextFileAtomic(file, j.dump());
}

}  // namespace swish::replay
