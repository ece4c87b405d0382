#include "swish/io/gltf_export.hpp"

#include <cstring>

#include <nlohmann/json.hpp>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"

namespace swish::io {
namespace {

constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

std::string base64(const std::vector<uint8_t>& b) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((b.size() + 2) / 3 * 4);
  for (size_t i = 0; i < b.size(); i += 3) {
    const uint32_t v =
        uint32_t(b[i]) << 16 | (i + 1 < b.size() ? uint32_t(b[i + 1]) << 8 : 0) | (i + 2 < b.size() ? b[i + 2] : 0);
    o += t[v >> 18 & 63];
    o += t[v >> 12 & 63];
    o += i + 1 < b.size() ? t[v >> 6 & 63] : '=';
    o += i + 2 < b.size() ? t[v & 63] : '=';
  }
  return o;
}

// The JSON and the binary buffer of a glTF asset, packed at the end as .glb or as .gltf text.
class GltfBuilder {
 public:
  nlohmann::json json = nlohmann::json::object();

  // Appends raw bytes as a buffer view (4-byte aligned), returns its index.
  int view(const void* data, size_t bytes, std::optional<int> target) {
    while (bin_.size() % 4) bin_.push_back(0);
    const size_t offset = bin_.size();
    bin_.resize(offset + bytes);
    if (bytes) std::memcpy(bin_.data() + offset, data, bytes);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) v["target"] = *target;
    json["bufferViews"].push_back(v);
    return int(json["bufferViews"].size()) - 1;
  }
  int accessor(const void* data, size_t count, int componentType, size_t componentSize, const char* type,
               int components, std::optional<int> target, bool minMax = false) {
    const int v = view(data, count * componentSize * size_t(components), target);
    nlohmann::json a = {{"bufferView", v}, {"componentType", componentType}, {"count", count}, {"type", type}};
    if (minMax && componentType == kFloat && count > 0) {
      const float* f = static_cast<const float*>(data);
      std::vector<float> lo(f, f + components), hi(f, f + components);
      for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < components; ++c) {
          lo[size_t(c)] = std::min(lo[size_t(c)], f[i * size_t(components) + size_t(c)]);
          hi[size_t(c)] = std::max(hi[size_t(c)], f[i * size_t(components) + size_t(c)]);
        }
      a["min"] = lo;
      a["max"] = hi;
    }
    json["accessors"].push_back(a);
    return int(json["accessors"].size()) - 1;
  }

  // .gltf: the buffer as a base64 data URI inside the JSON.
  std::string finishGltf() {
    while (bin_.size() % 4) bin_.push_back(0);
    json["buffers"] = nlohmann::json::array(
        {{{"byteLength", bin_.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin_)}}});
    return json.dump();
  }

  std::vector<uint8_t> finishGlb() {
    while (bin_.size() % 4) bin_.push_back(0);
    json["buffers"] = nlohmann::json::array({{{"byteLength", bin_.size()}}});
    std::string text = json.dump();
    while (text.size() % 4) text.push_back(' ');
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t x) {
      for (int k = 0; k < 4; ++k) out.push_back(uint8_t(x >> (8 * k)));
    };
    const size_t total = 12 + 8 + text.size() + 8 + bin_.size();
    if (total > 0xFFFFFFFFull) throw Error("glTF export: the scene is larger than 4 GiB");
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(uint32_t(total));
    u32(uint32_t(text.size()));
    u32(0x4E4F534A);  // "JSON"
    out.insert(out.end(), text.begin(), text.end());
    u32(uint32_t(bin_.size()));
    u32(0x004E4942);  // "BIN\0"
    out.insert(out.end(), bin_.begin(), bin_.end());
    return out;
  }

 private:
  std::vector<uint8_t> bin_;
};

nlohmann::json quatJson(const Quatf& q) { return {q.x(), q.y(), q.z(), q.w()}; }
nlohmann::json vecJson(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }

// Joint j is node j (buildScene writes the joints first). One sampler per joint rotation (and per
// root translation), all on one shared time accessor.
void addAnimation(GltfBuilder& b, const GltfScene& scene, const GltfAnimation& a) {
  const Skeleton* sk = scene.skeleton;
  if (!sk) throw Error("glTF export: animation '" + a.name + "' needs the scene's skeleton");
  if (!a.frames || a.frames->empty()) throw Error("glTF export: animation '" + a.name + "' has no frames");
  if (!(a.framesPerSecond > 0.f))
    throw Error("glTF export: animation '" + a.name + "': frames per second must be positive");
  const std::vector<Pose>& frames = *a.frames;
  const size_t n = frames.size();
  std::vector<float> times(n);
  for (size_t f = 0; f < n; ++f) {
    if (frames[f].local.size() != sk->size())
      throw Error("glTF export: animation '" + a.name + "' frame " + std::to_string(f) + " has " +
                  std::to_string(frames[f].local.size()) + " rotations for " + std::to_string(sk->size()) + " joints");
    times[f] = float(double(f) / double(a.framesPerSecond));
  }
  const int input = b.accessor(times.data(), n, kFloat, 4, "SCALAR", 1, std::nullopt, true);
  nlohmann::json samplers = nlohmann::json::array(), channels = nlohmann::json::array();
  auto channel = [&](const std::vector<float>& values, const char* type, int components, size_t node,
                     const char* path) {
    const int output = b.accessor(values.data(), n, kFloat, 4, type, components, std::nullopt);
    samplers.push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
    channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", path}}}});
  };
  for (size_t j = 0; j < sk->size(); ++j) {
    std::vector<float> q(n * 4);
    Quatf previous = Quatf::Identity();
    for (size_t f = 0; f < n; ++f) {
      Quatf r = frames[f].local[j].normalized();
      if (f > 0 && r.dot(previous) < 0.f) r.coeffs() = -r.coeffs();  // no long way round between keys
      previous = r;
      for (int c = 0; c < 4; ++c) q[f * 4 + size_t(c)] = r.coeffs()[c];  // x, y, z, w as glTF
    }
    channel(q, "VEC4", 4, j, "rotation");
    if (sk->joints[j].parent < 0) {
      std::vector<float> t(n * 3);
      for (size_t f = 0; f < n; ++f)
        for (int c = 0; c < 3; ++c) t[f * 3 + size_t(c)] = frames[f].rootTranslation[c];
      channel(t, "VEC3", 3, j, "translation");
    }
  }
  b.json["animations"] = nlohmann::json::array({{{"name", a.name}, {"samplers", samplers}, {"channels", channels}}});
}

void buildScene(GltfBuilder& b, const GltfScene& scene) {
  b.json["asset"] = {{"version", "2.0"}, {"generator", scene.generator}};
  b.json["scene"] = 0;
  b.json["nodes"] = nlohmann::json::array();
  b.json["meshes"] = nlohmann::json::array();
  nlohmann::json roots = nlohmann::json::array();

  // Skeleton: joint nodes first, so joint j is node j.
  int skin = -1;
  const Skeleton* sk = scene.skeleton;
  if (sk) {
    sk->validate("glTF export skeleton");
    if (sk->size() > 65535) throw Error("glTF export: more than 65535 joints");
    for (size_t j = 0; j < sk->size(); ++j) {
      const Joint& joint = sk->joints[j];
      nlohmann::json n = {{"name", joint.name}, {"translation", vecJson(joint.rest.translation)}};
      if (!joint.rest.rotation.coeffs().isApprox(Quatf::Identity().coeffs(), 0.f))
        n["rotation"] = quatJson(joint.rest.rotation);
      b.json["nodes"].push_back(n);
    }
    for (size_t j = 0; j < sk->size(); ++j) {
      const int p = sk->joints[j].parent;
      if (p < 0)
        roots.push_back(j);
      else
        b.json["nodes"][size_t(p)]["children"].push_back(j);
    }
    Skeleton withBind = *sk;
    if (withBind.inverseBind.empty()) withBind.computeInverseBindFromRest();
    std::vector<float> ibm;
    for (const Mat4f& m : withBind.inverseBind)
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) ibm.push_back(m(r, c));  // glTF matrices are column-major
    const int acc = b.accessor(ibm.data(), sk->size(), kFloat, 4, "MAT4", 16, std::nullopt);
    nlohmann::json joints = nlohmann::json::array();
    for (size_t j = 0; j < sk->size(); ++j) joints.push_back(j);
    b.json["skins"] =
        nlohmann::json::array({{{"joints", joints}, {"inverseBindMatrices", acc}, {"skeleton", roots[0]}}});
    skin = 0;
  }

  // Materials and their textures.
  for (const GltfMaterial& m : scene.materials) {
    nlohmann::json mat = {{"name", m.name},
                          {"pbrMetallicRoughness",
                           {{"baseColorFactor", {m.baseColor[0], m.baseColor[1], m.baseColor[2], m.baseColor[3]}},
                            {"metallicFactor", 0.0},
                            {"roughnessFactor", m.roughness}}}};
    const std::vector<uint8_t>& png = m.normalMapPng;
    if (!png.empty()) {
      static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
      if (png.size() < 8 || std::memcmp(png.data(), kSignature, 8) != 0)
        throw Error("glTF export: the normal map of material '" + m.name + "' is not a PNG");
      const int v = b.view(png.data(), png.size(), std::nullopt);
      b.json["images"].push_back({{"bufferView", v}, {"mimeType", "image/png"}, {"name", m.name + "_normal"}});
      if (!b.json.contains("samplers"))
        b.json["samplers"] = nlohmann::json::array({{{"magFilter", 9729}, {"minFilter", 9987}}});
      b.json["textures"].push_back({{"source", b.json["images"].size() - 1}, {"sampler", 0}});
      mat["normalTexture"] = {{"index", b.json["textures"].size() - 1}};
    }
    b.json["materials"].push_back(mat);
  }

  for (const GltfMeshEntry& e : scene.meshes) {
    if (!e.mesh) throw Error("glTF export: mesh '" + e.name + "' is null");
    const Mesh& m = *e.mesh;
    const bool skinned = e.skinned && sk && m.skin.vertexCount() == m.vertexCount() && m.vertexCount() > 0;
    m.validate("glTF export mesh '" + e.name + "'", sk ? sk->size() : 0);
    const size_t n = m.vertexCount();
    nlohmann::json attrs;
    attrs["POSITION"] = b.accessor(m.positions.data(), n, kFloat, 4, "VEC3", 3, kArrayBuffer, true);
    if (size_t(m.normals.rows()) == n && n)
      attrs["NORMAL"] = b.accessor(m.normals.data(), n, kFloat, 4, "VEC3", 3, kArrayBuffer);
    if (size_t(m.tangents.rows()) == n && n)
      attrs["TANGENT"] = b.accessor(m.tangents.data(), n, kFloat, 4, "VEC4", 4, kArrayBuffer);
    if (size_t(m.uvs.rows()) == n && n)
      attrs["TEXCOORD_0"] = b.accessor(m.uvs.data(), n, kFloat, 4, "VEC2", 2, kArrayBuffer);
    if (skinned) {
      const int inf = m.skin.influences;
      for (int set = 0; set * 4 < inf; ++set) {
        std::vector<uint16_t> joints(n * 4, 0);
        std::vector<float> weights(n * 4, 0.f);
        for (size_t v = 0; v < n; ++v)
          for (int k = 0; k < 4 && set * 4 + k < inf; ++k) {
            joints[v * 4 + size_t(k)] = m.skin.joints[v * size_t(inf) + size_t(set * 4 + k)];
            weights[v * 4 + size_t(k)] = m.skin.weights[v * size_t(inf) + size_t(set * 4 + k)];
          }
        attrs["JOINTS_" + std::to_string(set)] =
            b.accessor(joints.data(), n, kUnsignedShort, 2, "VEC4", 4, kArrayBuffer);
        attrs["WEIGHTS_" + std::to_string(set)] = b.accessor(weights.data(), n, kFloat, 4, "VEC4", 4, kArrayBuffer);
      }
    }
    nlohmann::json prim = {{"attributes", attrs}, {"mode", 4}};
    prim["indices"] =
        b.accessor(m.triangles.data(), m.triangleCount() * 3, kUnsignedInt, 4, "SCALAR", 1, kElementArrayBuffer);
    if (e.material) {
      if (*e.material >= scene.materials.size())
        throw Error("glTF export: mesh '" + e.name + "' refers to a missing material");
      prim["material"] = *e.material;
    }
    b.json["meshes"].push_back({{"name", e.name}, {"primitives", nlohmann::json::array({prim})}});
    nlohmann::json node = {{"name", e.name}, {"mesh", b.json["meshes"].size() - 1}};
    if (skinned)
      node["skin"] = skin;
    else {
      const Eigen::Vector3d t = e.preciseTranslation.value_or(e.transform.translation.cast<double>());
      node["translation"] = {t.x(), t.y(), t.z()};
      node["rotation"] = quatJson(e.transform.rotation);
    }
    b.json["nodes"].push_back(node);
    roots.push_back(b.json["nodes"].size() - 1);
  }
  if (scene.animation) addAnimation(b, scene, *scene.animation);
  b.json["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
}

}  // namespace

std::vector<uint8_t> encodeGlb(const GltfScene& scene) {
  GltfBuilder b;
  buildScene(b, scene);
  return b.finishGlb();
}

std::string encodeGltf(const GltfScene& scene) {
  GltfBuilder b;
  buildScene(b, scene);
  return b.finishGltf();
}

void writeGlb(const std::filesystem::path& file, const GltfScene& scene) {
  const std::vector<uint8_t> bytes = encodeGlb(scene);
  writeFileAtomic(file, bytes);
}

std::vector<uint8_t> encodeCharacterGlb(const Character& c, const std::vector<uint8_t>& garmentNormalMapPng) {
  GltfScene s;
  s.skeleton = &c.skeleton;
  s.generator = "swish (character " + c.name + ")";
  s.materials.push_back({"skin", Vec4f(0.80f, 0.66f, 0.55f, 1.f), 0.7f, {}});
  s.materials.push_back({"cloth", Vec4f(0.15f, 0.25f, 0.65f, 1.f), 0.9f, garmentNormalMapPng});
  s.meshes.push_back({"body", &c.body, true, 0, {}});
  s.meshes.push_back({"shirt", &c.garment, true, 1, {}});
  if (c.simulationMesh) s.meshes.push_back({"simulation", &*c.simulationMesh, true, 1, {}});
  return encodeGlb(s);
}

void writeCharacterGlb(const std::filesystem::path& file, const Character& c,
                       const std::vector<uint8_t>& garmentNormalMapPng) {
  writeFileAtomic(file, encodeCharacterGlb(c, garmentNormalMapPng));
}

}  // namespace swish::io
