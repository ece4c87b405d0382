// Character import: the shared CC0 test character exactly, and a clear Error for every bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>

#include <assimp/scene.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/io/character_import.hpp"
#include "swish/io/gltf_export.hpp"
#include "swish/io/mesh_topology_check.hpp"

using namespace swish;
namespace fs = std::filesystem;

namespace {

const fs::path kTestCharacter = test::sharedAsset("tshirt_lo.glb");

#define SKIP_WITHOUT_SHARED_CHARACTER()                              \
  if (!fs::exists(kTestCharacter))                                   \
  GTEST_SKIP() << "the shared CC0 test character " << kTestCharacter \
               << " is absent (../shared/assets beside the project); this test needs it"

using test::errorOf;

// Writes `bytes` to `p` and returns `p`.
fs::path writeFile(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

// A closed, outward-wound octahedron.
Mesh octahedron() {
  Mesh m;
  m.positions.resize(6, 3);
  m.positions << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  m.triangles.resize(8, 3);
  m.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return m;
}

}  // namespace

TEST(IoCharacterImport, SharedTestCharacterImportsExactly) {
  SKIP_WITHOUT_SHARED_CHARACTER();
  const Character c = io::importCharacter(kTestCharacter);
  EXPECT_EQ(c.skeleton.size(), 31u);
  EXPECT_EQ(c.body.vertexCount(), 14517u);
  EXPECT_EQ(c.body.triangleCount(), 26756u);
  EXPECT_EQ(c.garment.vertexCount(), 902u);
  EXPECT_EQ(c.garment.triangleCount(), 1528u);
  EXPECT_FALSE(c.simulationMesh.has_value());
  EXPECT_EQ(c.skeleton.joints[0].name, "Hips");
  EXPECT_EQ(c.skeleton.joints[0].parent, -1);
  const int spine1 = c.skeleton.find("Spine1"), leftArm = c.skeleton.find("LeftShoulder");
  ASSERT_GE(spine1, 0);
  ASSERT_GE(leftArm, 0);
  EXPECT_EQ(c.skeleton.joints[size_t(leftArm)].parent, spine1);
  // README: rest rotations are the identity, node translations are head - parent head, IBMs are
  // pure translations (the negated global head).
  const int leftUpLeg = c.skeleton.find("LeftUpLeg");
  EXPECT_NEAR(c.skeleton.joints[size_t(leftUpLeg)].rest.translation.x(), 0.110365f, 1e-6f);
  Vec3f head = Vec3f::Zero();
  for (int j = leftUpLeg; j >= 0; j = c.skeleton.joints[size_t(j)].parent)
    head += c.skeleton.joints[size_t(j)].rest.translation;
  for (const Joint& j : c.skeleton.joints) EXPECT_NEAR(j.rest.rotation.angularDistance(Quatf::Identity()), 0.f, 1e-5f);
  const Mat4f& ibm = c.skeleton.inverseBind[size_t(leftUpLeg)];
  EXPECT_LT((ibm.topLeftCorner<3, 3>() - Mat3f::Identity()).cwiseAbs().maxCoeff(), 1e-5f);
  EXPECT_LT((ibm.topRightCorner<3, 1>() + head).cwiseAbs().maxCoeff(), 1e-5f);
  // Feet at y = -0.817 (README), UVs in [0, 1] (glTF convention kept), weights valid.
  EXPECT_NEAR(c.body.positions.col(1).minCoeff(), -0.817f, 0.01f);
  EXPECT_GE(c.garment.uvs.minCoeff(), 0.f);
  EXPECT_LE(c.garment.uvs.maxCoeff(), 1.f);
  EXPECT_EQ(c.body.skin.influences, 4);
  for (size_t v = 0; v < c.garment.vertexCount(); ++v) {
    float s = 0;
    for (int k = 0; k < c.garment.skin.influences; ++k) s += c.garment.skin.weights[v * 4 + size_t(k)];
    ASSERT_NEAR(s, 1.f, 1e-5f) << "garment vertex " << v;
  }
  EXPECT_EQ(c.body.normals.rows(), c.body.positions.rows());
}

TEST(IoCharacterImport, MissingMeshesAndJointsNameWhatIsMissing) {
  SKIP_WITHOUT_SHARED_CHARACTER();
  io::CharacterImportOptions noBody;
  noBody.bodyNames = {"mannequin_that_is_not_there"};
  std::string e = errorOf([&] { io::importCharacter(kTestCharacter, noBody); });
  EXPECT_NE(e.find("no body mesh"), std::string::npos) << e;
  EXPECT_NE(e.find("'shirt'"), std::string::npos) << e;  // lists the meshes there are
  io::CharacterImportOptions noGarment;
  noGarment.garmentNames = {"cape"};
  e = errorOf([&] { io::importCharacter(kTestCharacter, noGarment); });
  EXPECT_NE(e.find("no garment mesh"), std::string::npos) << e;
  io::CharacterImportOptions needsTail;
  needsTail.requiredJoints = {"Spine", "Tail"};
  e = errorOf([&] { io::importCharacter(kTestCharacter, needsTail); });
  EXPECT_NE(e.find("'Tail'"), std::string::npos) << e;
  EXPECT_EQ(e.find("'Spine'"), std::string::npos) << e;
}

TEST(IoCharacterImport, MissingAndCorruptFilesGiveErrorsNamingTheFile) {
  std::string e = errorOf([] { io::importCharacter("/nonexistent/dir/char.glb"); });
  EXPECT_NE(e.find("/nonexistent/dir/char.glb"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;

  const test::TempDir tmp("test_io");
  const fs::path junk = writeFile(tmp / "junk.glb", std::string("glTF\x02\0\0\0garbage that is not a glb", 33));
  e = errorOf([&] { io::importCharacter(junk); });
  EXPECT_NE(e.find(junk.string()), std::string::npos) << e;

  if (fs::exists(kTestCharacter)) {  // a real file cut in half
    std::ifstream in(kTestCharacter, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const fs::path half = writeFile(tmp / "half.glb", bytes.substr(0, bytes.size() / 2));
    e = errorOf([&] { io::importCharacter(half); });
    EXPECT_NE(e.find(half.string()), std::string::npos) << e;
  }
  // A file with meshes but no skin.
  const fs::path obj = writeFile(tmp / "plain.obj", "o body\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  e = errorOf([&] { io::importCharacter(obj); });
  EXPECT_NE(e.find("no skin"), std::string::npos) << e;
}

TEST(IoMeshTopology, ClosedOutwardMeshPasses) {
  const Mesh m = octahedron();
  const auto r = io::analyseTopology(m);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.inconsistentEdges, 0u);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_GT(r.signedVolume, 0.0);
  EXPECT_NO_THROW(io::checkGarmentTopology(m, "octahedron"));
}

TEST(IoMeshTopology, FlippedTriangleInvertedMeshAndNonManifoldEdgeAreRefused) {
  Mesh flipped = octahedron();
  std::swap(flipped.triangles(3, 1), flipped.triangles(3, 2));
  std::string e = errorOf([&] { io::checkGarmentTopology(flipped, "shirt"); });
  EXPECT_NE(e.find("flipped"), std::string::npos) << e;

  Mesh inverted = octahedron();
  inverted.triangles.col(1).swap(inverted.triangles.col(2));
  e = errorOf([&] { io::checkGarmentTopology(inverted, "shirt"); });
  EXPECT_NE(e.find("inside out"), std::string::npos) << e;

  Mesh fin = octahedron();  // a third triangle on edge 0-2
  fin.positions.conservativeResize(7, 3);
  fin.positions.row(6) = Eigen::RowVector3f(1, 1, 1);
  fin.triangles.conservativeResize(9, 3);
  fin.triangles.row(8) << 0, 2, 6;
  e = errorOf([&] { io::checkGarmentTopology(fin, "shirt"); });
  EXPECT_NE(e.find("non-manifold"), std::string::npos) << e;
}

TEST(IoCharacterImport, SharedGarmentPassesTopologyChecks) {
  SKIP_WITHOUT_SHARED_CHARACTER();
  const Character c = io::importCharacter(kTestCharacter);
  const auto r = io::analyseTopology(c.garment);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.inconsistentEdges, 0u);
  EXPECT_GT(r.boundaryEdges, 0u);  // hem, collar, sleeves
  EXPECT_GT(r.normalAgreement, 0.9);
}

TEST(IoCharacterImport, FbxPathReadsWhatGltfHolds) {
  // No FBX asset ships with the project: make one with assimp's own FBX (ASCII) exporter from the
  // default character's .glb, and check the FBX route (joined vertices, FBX node conventions) gives
  // the same character.
  const Character c = bake::makeDefaultCharacter();
  const test::TempDir tmp("test_io");
  const fs::path glb = writeFile(tmp / "fbxsrc.glb", "");
  io::writeCharacterGlb(glb, c);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(glb.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  const fs::path fbx = tmp / "char.fbx";
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, "fbxa", fbx.string()), AI_SUCCESS) << exporter.GetErrorString();
  const Character back = io::importCharacter(fbx);
  EXPECT_EQ(back.skeleton.size(), c.skeleton.size());
  ASSERT_EQ(back.body.vertexCount(), c.body.vertexCount());
  ASSERT_EQ(back.garment.vertexCount(), c.garment.vertexCount());
  // The FBX route re-orders vertices (faces are written per corner, then identical corners joined):
  // every imported vertex must match some original vertex in position and UV.
  float worst = 0;
  for (Eigen::Index v = 0; v < back.garment.positions.rows(); ++v) {
    float best = INFINITY;
    for (Eigen::Index u = 0; u < c.garment.positions.rows() && best > 1e-6f; ++u)
      best = std::min(best, std::max((back.garment.positions.row(v) - c.garment.positions.row(u)).cwiseAbs().maxCoeff(),
                                     (back.garment.uvs.row(v) - c.garment.uvs.row(u)).cwiseAbs().maxCoeff()));
    worst = std::max(worst, best);
  }
  EXPECT_LT(worst, 1e-4f);
  for (const char* j : {"Hips", "Spine1", "LeftArm", "RightHandFinger1"}) EXPECT_GE(back.skeleton.find(j), 0) << j;
}
