// glTF export: the default character and the shared test character survive a write -> import round
// trip exactly (up to float printing: none, the data is binary), the .glb is well formed and
// deterministic, normal maps are embedded, and the committed default-character .glb is current.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/io/character_import.hpp"
#include "swish/io/gltf_export.hpp"

using namespace swish;
namespace fs = std::filesystem;

namespace {

nlohmann::json glbJson(const std::vector<uint8_t>& glb) {
  uint32_t len = 0;
  std::memcpy(&len, glb.data() + 12, 4);
  return nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + long(len));
}

void expectSameMesh(const Mesh& a, const Mesh& b, const std::string& what) {
  ASSERT_EQ(a.vertexCount(), b.vertexCount()) << what;
  ASSERT_EQ(a.triangleCount(), b.triangleCount()) << what;
  EXPECT_LT((a.positions - b.positions).cwiseAbs().maxCoeff(), 1e-6f) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
  if (a.uvs.rows()) {
    EXPECT_LT((a.uvs - b.uvs).cwiseAbs().maxCoeff(), 1e-7f) << what;
  }
  // Skin: the same (joint, weight) pairs per vertex; the importer drops zero weights, so widths may differ.
  auto pairs = [](const Mesh& m, size_t v) {
    std::map<int, float> w;
    for (int k = 0; k < m.skin.influences; ++k) {
      const size_t i = v * size_t(m.skin.influences) + size_t(k);
      if (m.skin.weights[i] > 0.f) w[m.skin.joints[i]] += m.skin.weights[i];
    }
    return w;
  };
  for (size_t v = 0; v < a.vertexCount(); ++v) {
    const auto wa = pairs(a, v), wb = pairs(b, v);
    ASSERT_EQ(wa.size(), wb.size()) << what << " vertex " << v;
    for (const auto& [j, w] : wa) {
      ASSERT_TRUE(wb.count(j)) << what << " vertex " << v << " joint " << j;
      ASSERT_NEAR(w, wb.at(j), 1e-6f) << what << " vertex " << v;
    }
  }
}

}  // namespace

TEST(IoGltfExport, DefaultCharacterRoundTripsThroughTheImporter) {
  const Character c = bake::makeDefaultCharacter();
  const test::TempDir tmp("test_gltf");
  const fs::path p = tmp / "default.glb";
  io::writeCharacterGlb(p, c);
  const Character back = io::importCharacter(p);
  ASSERT_EQ(back.skeleton.size(), c.skeleton.size());
  for (size_t j = 0; j < c.skeleton.size(); ++j) {
    EXPECT_EQ(back.skeleton.joints[j].name, c.skeleton.joints[j].name);
    EXPECT_EQ(back.skeleton.joints[j].parent, c.skeleton.joints[j].parent);
    EXPECT_LT((back.skeleton.joints[j].rest.translation - c.skeleton.joints[j].rest.translation).norm(), 1e-6f);
  }
  expectSameMesh(c.body, back.body, "body");
  expectSameMesh(c.garment, back.garment, "jersey");
}

TEST(IoGltfExport, SharedCharacterRoundTrips) {
  const fs::path shared = test::sharedAsset("tshirt_lo.glb");
  if (!fs::exists(shared)) GTEST_SKIP() << "the shared test character " << shared << " is absent";
  const Character c = io::importCharacter(shared);
  const test::TempDir tmp("test_gltf");
  const fs::path p = tmp / "shared.glb";
  io::writeCharacterGlb(p, c);
  const Character back = io::importCharacter(p);
  expectSameMesh(c.body, back.body, "body");
  expectSameMesh(c.garment, back.garment, "shirt");
}

TEST(IoGltfExport, WellFormedDeterministicWithEmbeddedNormalMap) {
  const Character c = bake::makeDefaultCharacter();
  // Smallest valid PNG signature + IHDR-less payload is enough for embedding (it is not decoded here).
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 1, 2, 3};
  const auto a = io::encodeCharacterGlb(c, png), b = io::encodeCharacterGlb(c, png);
  EXPECT_EQ(a, b);
  ASSERT_GT(a.size(), 20u);
  uint32_t magic = 0, total = 0;
  std::memcpy(&magic, a.data(), 4);
  std::memcpy(&total, a.data() + 8, 4);
  EXPECT_EQ(magic, 0x46546C67u);
  EXPECT_EQ(total, a.size());
  const auto j = glbJson(a);
  EXPECT_EQ(j["asset"]["version"], "2.0");
  ASSERT_EQ(j["images"].size(), 1u);
  EXPECT_EQ(j["materials"][1]["normalTexture"]["index"], 0);
  EXPECT_EQ(j["skins"][0]["joints"].size(), 31u);
  const auto& shirtAttrs = j["meshes"][1]["primitives"][0]["attributes"];
  for (const char* k : {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "JOINTS_0", "WEIGHTS_0"})
    EXPECT_TRUE(shirtAttrs.contains(k)) << k;

  std::vector<uint8_t> notPng = {1, 2, 3};
  EXPECT_THROW(io::encodeCharacterGlb(c, notPng), Error);
  EXPECT_THROW(io::writeCharacterGlb("/nonexistent-dir/x/y.glb", c), Error);
}

TEST(IoGltfExport, UnskinnedMeshesAndSeveralNodes) {
  Mesh tri;
  tri.positions.resize(3, 3);
  tri.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  tri.triangles.resize(1, 3);
  tri.triangles << 0, 1, 2;
  io::GltfScene s;
  s.meshes.push_back({"a", &tri, false, std::nullopt, {}});
  s.meshes.push_back({"b", &tri, false, std::nullopt, {Quatf::Identity(), Vec3f(2, 0, 0)}});
  const auto j = glbJson(io::encodeGlb(s));
  EXPECT_EQ(j["nodes"].size(), 2u);
  EXPECT_EQ(j["nodes"][1]["translation"][0], 2.0);
  EXPECT_FALSE(j.contains("skins"));
}

TEST(IoGltfExport, GltfTextHoldsTheGlbContentAndPreciseTranslations) {
  const Character c = bake::makeDefaultCharacter();
  io::GltfScene s;
  s.generator = "test";
  s.meshes.push_back({"a", &c.garment, false, std::nullopt, {Quatf(0.f, 0.f, 1.f, 0.f), Vec3f(2, 0, 0)}});
  s.meshes.push_back({"b", &c.garment, false, std::nullopt, {}});
  s.meshes.back().preciseTranslation = Eigen::Vector3d(1e4 + 1e-4, -3.25, 0.1);
  const auto glb = io::encodeGlb(s);
  const auto text = nlohmann::json::parse(io::encodeGltf(s));
  // The JSON is the .glb's, the buffer moved into a base64 data URI.
  nlohmann::json same = text;
  const std::string uri = same["buffers"][0]["uri"].get<std::string>();
  same["buffers"][0].erase("uri");
  EXPECT_EQ(same, glbJson(glb));
  const std::string prefix = "data:application/octet-stream;base64,";
  ASSERT_EQ(uri.rfind(prefix, 0), 0u);
  std::vector<uint8_t> bin;
  uint32_t bits = 0;
  int have = 0;
  for (char ch : uri.substr(prefix.size())) {
    if (ch == '=') break;
    const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    bits = bits << 6 | uint32_t(alphabet.find(ch));
    if ((have += 6) >= 8) bin.push_back(uint8_t(bits >> (have -= 8)));
  }
  uint32_t jsonLen = 0, binLen = 0;
  std::memcpy(&jsonLen, glb.data() + 12, 4);
  std::memcpy(&binLen, glb.data() + 20 + jsonLen, 4);
  ASSERT_EQ(bin.size(), binLen);
  EXPECT_EQ(std::memcmp(bin.data(), glb.data() + 28 + jsonLen, binLen), 0);
  // Float transforms as before; the double translation kept exactly.
  EXPECT_EQ(text["nodes"][0]["translation"][0], 2.0);
  EXPECT_EQ(text["nodes"][0]["rotation"][1], 1.0);
  EXPECT_EQ(text["nodes"][1]["translation"][0].get<double>(), 1e4 + 1e-4);
  EXPECT_EQ(text["nodes"][1]["translation"][1].get<double>(), -3.25);
  EXPECT_EQ(text["nodes"][1]["translation"][2].get<double>(), 0.1);
}

TEST(IoGltfExport, CommittedDefaultCharacterGlbIsCurrent) {
  const fs::path committed = test::sourceDir() / "assets/default/default_character.glb";
  ASSERT_TRUE(fs::exists(committed)) << committed;
  EXPECT_LT(fs::file_size(committed), 1u << 20) << "the committed preview must stay under 1 MB";
  const Character fresh = bake::makeDefaultCharacter();
  const Character stored = io::importCharacter(committed);
  // Compared after import rather than byte for byte, so that a build with other float code generation
  // still passes; 1e-5 m catches any real change of the recipe or the generator.
  ASSERT_EQ(stored.body.vertexCount(), fresh.body.vertexCount()) << "regenerate " << committed;
  ASSERT_EQ(stored.garment.vertexCount(), fresh.garment.vertexCount()) << "regenerate " << committed;
  EXPECT_LT((stored.garment.positions - fresh.garment.positions).cwiseAbs().maxCoeff(), 1e-5f);
  EXPECT_LT((stored.body.positions - fresh.body.positions).cwiseAbs().maxCoeff(), 1e-5f);
}
