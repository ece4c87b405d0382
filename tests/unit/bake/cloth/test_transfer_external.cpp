// Simulations made elsewhere: the BVH transition clip re-imports (assimp) to the same rotations; the
// OBJ reader maps results by vertex order and rejects bad files with file:line errors; the shape
// source (ExternalShapeSource) takes a folder of per-pose files or one multi-frame glTF, in character
// or world space, uses meshes in the simulation mesh's order as they are and binds re-meshed ones by
// closest point; the bake config's part1.simulation source keys are checked.
// (The whole round trip through `swish bake` is tests/e2e/test_bake_external.cpp.)
#include <gtest/gtest.h>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/cloth/external_simulation.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/mesh_import.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

TEST(ExternalSimulation, TransitionClipReimportsWithAssimpToTheSameRotations) {
  Rng rng(test::testSeed(701));
  const Model m = test::makeRandomModel(rng);
  const Skeleton& sk = m.skeleton;
  std::vector<Pose> targets;
  for (int i = 0; i < 3; ++i) targets.push_back(test::makeRandomPose(rng, sk, 1.2f));
  TransitionClipSettings s;
  s.framesPerSecond = 10.f;
  std::vector<TransitionMarker> markers;
  const std::vector<Pose> frames = buildTransitionFrames(sk, targets, s, markers);
  ASSERT_EQ(markers.size(), 3u);
  EXPECT_EQ(frames.size(), 3u * (10 + 1 + 5));
  for (size_t i = 0; i < 3; ++i) {
    // Starts at the A-pose, ends (and holds) at the target.
    for (size_t j = 0; j < sk.size(); ++j) {
      EXPECT_GT(std::abs(frames[markers[i].firstFrame].local[j].dot(sk.restPose().local[j])), 1.f - 1e-6f);
      EXPECT_GT(std::abs(frames[markers[i].targetFrame].local[j].dot(targets[i].local[j])), 1.f - 1e-6f);
    }
  }
  const test::TempDir tmp("test_external_bvh");
  const fs::path dir = tmp.path();
  const fs::path bvh = dir / "poses.bvh";
  writeTransitionBvh(bvh, sk, targets, s);
  ASSERT_TRUE(fs::exists(dir / "poses.bvh.markers.json"));

  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(bvh.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  ASSERT_EQ(scene->mNumAnimations, 1u);
  const aiAnimation* anim = scene->mAnimations[0];
  size_t checked = 0;
  for (unsigned c = 0; c < anim->mNumChannels; ++c) {
    const aiNodeAnim* ch = anim->mChannels[c];
    const int j = sk.find(ch->mNodeName.C_Str());
    if (j < 0) continue;  // End Site nodes
    ASSERT_EQ(ch->mNumRotationKeys, frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      const aiQuaternion& q = ch->mRotationKeys[f].mValue;
      const Quatf got(q.w, q.x, q.y, q.z);
      EXPECT_GT(std::abs(got.normalized().dot(frames[f].local[size_t(j)])), 1.f - 1e-5f)
          << "joint " << sk.joints[size_t(j)].name << " frame " << f;
      ++checked;
    }
  }
  EXPECT_EQ(checked, sk.size() * frames.size());
}

TEST(ExternalSimulation, ObjReaderMapsByVertexOrderAndRejectsBadFiles) {
  const test::TempDir tmp("test_external_obj");
  const fs::path dir = tmp.path();
  const fs::path good = dir / "good.obj";
  std::ofstream(good) << "# a quad\nv 0 0 0\nv 1 0 0\r\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                         "f 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -3//1 -2//1\n";
  const ObjMesh m = readObj(good);
  ASSERT_EQ(m.positions.rows(), 4);
  EXPECT_EQ(m.positions(2, 1), 1.f);
  ASSERT_EQ(m.triangles.rows(), 3);  // quad fan (2) + one triangle
  EXPECT_EQ(m.triangles.row(1), (Eigen::Matrix<uint32_t, 1, 3>() << 0, 2, 3).finished());
  EXPECT_EQ(m.triangles.row(2), (Eigen::Matrix<uint32_t, 1, 3>() << 0, 1, 2).finished());
  EXPECT_EQ(importSimulatedPositions(good, 4), m.positions);

  auto expectError = [&](const std::string& body, const std::string& needle,
                         std::source_location where = std::source_location::current()) {
    const fs::path p = dir / "bad.obj";
    std::ofstream(p) << body;
    const std::string e = test::errorOf([&] { readObj(p); }, where);
    EXPECT_NE(e.find(needle), std::string::npos) << e;
  };
  expectError("v 0 0\n", "bad.obj:1");
  expectError("v 0 0 0\nv 1 nan 0\n", "bad.obj:2");
  expectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "bad.obj:4");
  expectError("v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj:3");
  expectError("v 0 0 0\nf 1 x 2\n", "bad.obj:2");
  expectError("v 0 0 0\nf 0 1 1\n", "bad.obj:2");
  expectError("# nothing\n", "no vertices");
  expectError("v 1e99999 0 0\n", "bad.obj:1");
  try {
    importSimulatedPositions(good, 5);
    ADD_FAILURE() << "count mismatch must be an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("good.obj"), std::string::npos);
  }
  EXPECT_THROW(readObj(dir / "missing.obj"), Error);
}

namespace {

// A curved 6 x 5 sheet (the "simulation mesh" of the tests below): metres, about 0.5 m across.
struct Sheet {
  Points3f rest;
  Triangles tris;
};
Sheet makeSheet() {
  const int nx = 6, ny = 5;
  Sheet s;
  s.rest.resize(nx * ny, 3);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
      s.rest.row(y * nx + x) = Vec3f(0.1f * float(x), 1.f + 0.1f * float(y), 0.05f * std::sin(0.7f * float(x + y)));
  std::vector<uint32_t> t;
  for (int y = 0; y + 1 < ny; ++y)
    for (int x = 0; x + 1 < nx; ++x) {
      const uint32_t a = uint32_t(y * nx + x), b = a + 1, c = a + uint32_t(nx), d = c + 1;
      t.insert(t.end(), {a, b, d, a, d, c});
    }
  s.tris = Eigen::Map<const Triangles>(t.data(), Eigen::Index(t.size() / 3), 3);
  return s;
}

// A smooth deformation standing in for a simulated pose.
Points3f bend(const Points3f& p, float amount) {
  Points3f o = p;
  for (Eigen::Index v = 0; v < p.rows(); ++v) {
    o(v, 2) += amount * p(v, 0) * p(v, 0);
    o(v, 1) -= 0.5f * amount * p(v, 0);
  }
  return o;
}

// The same mesh in another vertex order (new vertex k is old vertex order[k]).
void permute(const Points3f& p, const Triangles& t, Points3f& outP, Triangles& outT,
             const std::vector<uint32_t>& order) {
  std::vector<uint32_t> inv(order.size());
  outP.resize(p.rows(), 3);
  for (uint32_t k = 0; k < order.size(); ++k) {
    inv[order[k]] = k;
    outP.row(k) = p.row(order[k]);
  }
  outT = t;
  for (Eigen::Index f = 0; f < t.rows(); ++f)
    for (int c = 0; c < 3; ++c) outT(f, c) = inv[t(f, c)];
}

void writeObjFile(const fs::path& f, const Points3f& p, const Triangles& t) { writeTextFileAtomic(f, objText(p, t)); }

float maxDiff(const Points3f& a, const Points3f& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

TEST(ExternalSimulation, FolderOfPoseFilesInTheSimulationMeshOrderIsUsedAsItIs) {
  const test::TempDir tmp("test_external_folder");
  const Sheet sh = makeSheet();
  const std::vector<uint32_t> targets = {10, 25, 40};
  writeObjFile(tmp / "pose_000000.obj", bend(sh.rest, 0.3f), sh.tris);
  // A point cloud (no faces) in the simulation mesh's order is taken too.
  writeTextFileAtomic(tmp / "pose_000001.obj", objText(bend(sh.rest, -0.2f), Triangles()));
  ExternalSimulationSettings es;
  es.path = tmp.path();
  const ExternalShapeSource src(es, sh.rest, sh.tris, targets, 1234);
  EXPECT_EQ(src.shape(0), bend(sh.rest, 0.3f));  // 9 significant digits give floats back exactly
  EXPECT_EQ(src.shape(1), bend(sh.rest, -0.2f));
  EXPECT_EQ(src.maxBindingDistance(), 0.f);
  // Pose 2 has no file: an error naming the file, never a zero shape.
  const std::string missing = test::errorOf([&] { src.shape(2); });
  EXPECT_NE(missing.find("pose_000002.obj: missing"), std::string::npos) << missing;
  EXPECT_NE(test::errorOf([&] { src.shape(3); }).find("not in the pose list"), std::string::npos);

  // Two results for one pose; another vertex count; the same count in another order (faces tell).
  writeObjFile(tmp / "pose_000002.obj", sh.rest, sh.tris);
  std::ofstream(tmp / "pose_000002.glb") << "not a glb";
  EXPECT_NE(test::errorOf([&] { src.shape(2); }).find("two results for one pose"), std::string::npos);
  fs::remove(tmp / "pose_000002.glb");
  writeObjFile(tmp / "pose_000002.obj", sh.rest.topRows(10), Triangles());
  std::string e = test::errorOf([&] { src.shape(2); });
  EXPECT_NE(e.find("10 vertices, the simulation mesh (garment.obj) has 30"), std::string::npos) << e;
  std::vector<uint32_t> order(30);
  for (uint32_t i = 0; i < 30; ++i) order[i] = (i * 7) % 30;
  Points3f pp;
  Triangles pt;
  permute(sh.rest, sh.tris, pp, pt, order);
  writeObjFile(tmp / "pose_000002.obj", pp, pt);
  e = test::errorOf([&] { src.shape(2); });
  EXPECT_NE(e.find("in another order"), std::string::npos) << e;
  EXPECT_NE(e.find("rest.obj"), std::string::npos) << e;
  std::ofstream(tmp / "pose_000002.obj", std::ios::trunc) << "v 0 0 0\nv nan 0 0\n";
  e = test::errorOf([&] { src.shape(2); });
  EXPECT_NE(e.find("pose_000002.obj:2"), std::string::npos) << e;
}

TEST(ExternalSimulation, AReMeshedGarmentIsBoundThroughItsRestShape) {
  const test::TempDir tmp("test_external_remesh");
  const Sheet sh = makeSheet();
  // Re-meshed: another vertex order and every quad split along the other diagonal, so no face is the
  // simulation mesh's. The simulation vertices lie on its vertices: binding must reproduce them.
  std::vector<uint32_t> t;
  for (int y = 0; y + 1 < 5; ++y)
    for (int x = 0; x + 1 < 6; ++x) {
      const uint32_t a = uint32_t(y * 6 + x), b = a + 1, c = a + 6, d = c + 1;
      t.insert(t.end(), {a, b, c, b, d, c});
    }
  const Triangles other = Eigen::Map<const Triangles>(t.data(), Eigen::Index(t.size() / 3), 3);
  std::vector<uint32_t> order(30);
  for (uint32_t i = 0; i < 30; ++i) order[i] = (i * 11) % 30;
  Points3f restP, poseP;
  Triangles rt, pt;
  permute(sh.rest, other, restP, rt, order);
  permute(bend(sh.rest, 0.3f), other, poseP, pt, order);
  writeObjFile(tmp / "rest.obj", restP, rt);
  writeObjFile(tmp / "pose_000000.obj", poseP, pt);
  ExternalSimulationSettings es;
  es.path = tmp.path();
  const ExternalShapeSource src(es, sh.rest, sh.tris, {5}, 1);
  EXPECT_LT(src.maxBindingDistance(), 1e-6f);
  EXPECT_LT(maxDiff(src.shape(0), bend(sh.rest, 0.3f)), 1e-5f);
  EXPECT_NE(src.description().find("re-meshed"), std::string::npos) << src.description();
  // A pose file whose count is neither the simulation mesh's nor the rest mesh's.
  writeObjFile(tmp / "pose_000000.obj", poseP.topRows(12), Triangles());
  const std::string e = test::errorOf([&] { src.shape(0); });
  EXPECT_NE(e.find("the re-meshed rest mesh"), std::string::npos) << e;

  // A rest mesh 10 cm off the garment (centimetres taken for metres, another garment): refused.
  writeObjFile(tmp / "rest.obj", restP.array() + 0.1f, rt);
  const std::string far = test::errorOf([&] { ExternalShapeSource(es, sh.rest, sh.tris, {5}, 1); });
  EXPECT_NE(far.find("rest.obj"), std::string::npos) << far;
  EXPECT_NE(far.find("bound 50 mm"), std::string::npos) << far;
}

TEST(ExternalSimulation, WorldSpaceResultsComeBackToCharacterSpace) {
  const test::TempDir tmp("test_external_world");
  const Sheet sh = makeSheet();
  ExternalSimulationSettings es;
  es.path = tmp.path();
  es.worldSpace = true;
  es.unitsPerMetre = 100.0;  // centimetres
  es.upAxis = 'z';
  es.origin = Vec3d(250.0, -40.0, 3.0);
  // What a Z-up centimetre tool writes: world = origin + 100 * (x, -z, y).
  const Points3f shape = bend(sh.rest, 0.3f);
  Points3f world(shape.rows(), 3);
  for (Eigen::Index v = 0; v < shape.rows(); ++v)
    world.row(v) = (es.origin + 100.0 * Vec3d(shape(v, 0), -shape(v, 2), shape(v, 1))).cast<float>().transpose();
  writeObjFile(tmp / "pose_000000.obj", world, sh.tris);
  const ExternalShapeSource src(es, sh.rest, sh.tris, {5}, 1);
  // float32 world coordinates of ~300 units keep ~2e-5 units = 0.2 um.
  EXPECT_LT(maxDiff(src.shape(0), shape), 1e-6f);
  EXPECT_EQ(es.toCharacter(es.origin), Vec3f::Zero());
  EXPECT_LT((es.toCharacter(es.origin + Vec3d(0, 0, 100)) - Vec3f(0, 1, 0)).norm(), 1e-6f);  // world up is Y
}

TEST(ExternalSimulation, ResultsForAnotherPoseListAreRefused) {
  const test::TempDir tmp("test_external_digest");
  const Sheet sh = makeSheet();
  fs::create_directories(tmp / "results");
  writeTextFileAtomic(tmp / "poses.json", nlohmann::json({{"pose_list_digest", "42"}}).dump());
  ExternalSimulationSettings es;
  es.path = tmp / "results";
  EXPECT_NO_THROW(ExternalShapeSource(es, sh.rest, sh.tris, {5}, 42));
  const std::string e = test::errorOf([&] { ExternalShapeSource(es, sh.rest, sh.tris, {5}, 43); });
  EXPECT_NE(e.find("another pose list"), std::string::npos) << e;
  es.path = tmp / "nowhere";
  EXPECT_NE(test::errorOf([&] { ExternalShapeSource(es, sh.rest, sh.tris, {5}, 42); }).find("not there"),
            std::string::npos);
}

namespace {

// A .gltf holding `base` with one morph target per frame (glTF stores targets as offsets from the
// base), target names in mesh.extras.targetNames as Blender writes them.
void writeMorphGltf(const fs::path& file, const Points3f& base, const Triangles& tris,
                    const std::vector<Points3f>& frames, const std::vector<std::string>& names) {
  std::vector<uint8_t> bin;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  auto add = [&](const void* data, size_t bytes, size_t count, int type, const char* kind, const Points3f* bounds) {
    const size_t offset = bin.size();
    bin.insert(bin.end(), static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
    views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    nlohmann::json a = {{"bufferView", views.size() - 1}, {"componentType", type}, {"count", count}, {"type", kind}};
    if (bounds) {
      const Vec3f lo = bounds->colwise().minCoeff(), hi = bounds->colwise().maxCoeff();
      a["min"] = {lo.x(), lo.y(), lo.z()};
      a["max"] = {hi.x(), hi.y(), hi.z()};
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  };
  const size_t n = size_t(base.rows());
  const size_t pos = add(base.data(), n * 12, n, 5126, "VEC3", &base);
  const size_t idx = add(tris.data(), size_t(tris.size()) * 4, size_t(tris.size()), 5125, "SCALAR", nullptr);
  nlohmann::json targets = nlohmann::json::array();
  for (const Points3f& f : frames) {
    const Points3f d = f - base;
    targets.push_back({{"POSITION", add(d.data(), n * 12, n, 5126, "VEC3", &d)}});
  }
  std::string b64;
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (size_t i = 0; i < bin.size(); i += 3) {
    const uint32_t v = uint32_t(bin[i]) << 16 | (i + 1 < bin.size() ? uint32_t(bin[i + 1]) << 8 : 0) |
                       (i + 2 < bin.size() ? bin[i + 2] : 0);
    b64 += t[v >> 18 & 63];
    b64 += t[v >> 12 & 63];
    b64 += i + 1 < bin.size() ? t[v >> 6 & 63] : '=';
    b64 += i + 2 < bin.size() ? t[v & 63] : '=';
  }
  nlohmann::json mesh = {
      {"name", "garment"},
      {"primitives", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"targets", targets}}}},
      {"weights", std::vector<float>(frames.size(), 0.f)}};
  if (!names.empty()) mesh["extras"] = {{"targetNames", names}};
  const nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"name", "garment"}, {"mesh", 0}}}},
      {"meshes", {mesh}},
      {"buffers", {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + b64}}}},
      {"bufferViews", views},
      {"accessors", accessors}};
  writeTextFileAtomic(file, j.dump());
}

}  // namespace

TEST(ExternalSimulation, OneMultiFrameGltfHoldsThePosesAsMorphTargets) {
  const test::TempDir tmp("test_external_morph");
  const Sheet sh = makeSheet();
  const std::vector<Points3f> shapes = {bend(sh.rest, 0.3f), bend(sh.rest, -0.2f), bend(sh.rest, 0.1f)};
  ExternalSimulationSettings es;
  es.path = tmp / "cache.gltf";
  // One target per pose, in pose order (offsets in the file: absolute positions back, to float rounding).
  writeMorphGltf(es.path, sh.rest, sh.tris, shapes, {});
  {
    const ExternalShapeSource src(es, sh.rest, sh.tris, {10, 20, 30}, 1);
    for (uint32_t i = 0; i < 3; ++i) EXPECT_LT(maxDiff(src.shape(i), shapes[i]), 1e-6f) << "pose " << i;
    EXPECT_NE(src.description().find("in pose order"), std::string::npos) << src.description();
  }
  // Named pose_<id>: matched by name whatever the order; a pose without a target is an error.
  writeMorphGltf(es.path, sh.rest, sh.tris, {shapes[2], shapes[0]}, {"pose_2", "pose_0"});
  {
    const ExternalShapeSource src(es, sh.rest, sh.tris, {10, 20, 30}, 1);
    EXPECT_LT(maxDiff(src.shape(0), shapes[0]), 1e-6f);
    EXPECT_LT(maxDiff(src.shape(2), shapes[2]), 1e-6f);
    EXPECT_NE(test::errorOf([&] { src.shape(1); }).find("no frame named pose_1"), std::string::npos);
  }
  // One target per clip frame: each pose at its target frame.
  std::vector<Points3f> perFrame(4, sh.rest);
  perFrame[3] = shapes[1];
  perFrame[1] = shapes[0];
  writeMorphGltf(es.path, sh.rest, sh.tris, perFrame, {});
  {
    const ExternalShapeSource src(es, sh.rest, sh.tris, {1, 3}, 1);
    EXPECT_LT(maxDiff(src.shape(0), shapes[0]), 1e-6f);
    EXPECT_LT(maxDiff(src.shape(1), shapes[1]), 1e-6f);
  }
  // Frames that map to nothing.
  writeMorphGltf(es.path, sh.rest, sh.tris, {shapes[0], shapes[1]}, {});
  const std::string e = test::errorOf([&] { ExternalShapeSource(es, sh.rest, sh.tris, {10, 20, 30}, 1); });
  EXPECT_NE(e.find("has 2 frames"), std::string::npos) << e;
}

TEST(ExternalSimulation, BakeConfigChecksTheSourceKeys) {
  const test::TempDir tmp("test_external_config");
  fs::create_directories(tmp / "results");
  const nlohmann::json base = {{"output", "out"},
                               {"part1", {{"clips", {"clip.bvh"}}, {"thinning", {{"target_poses", 10}}}}}};
  std::ofstream(tmp / "clip.bvh") << "HIERARCHY\n";
  auto parse = [&](const nlohmann::json& sim) {
    nlohmann::json j = base;
    j["part1"]["simulation"] = sim;
    return parseBakeConfig(j, "x.json", tmp.path());
  };
  auto errorFor = [&](const nlohmann::json& sim) { return test::errorOf([&] { parse(sim); }); };
  const BakeConfig c = parse({{"source", "external"}, {"path", "results"}});
  ASSERT_TRUE(c.part1);
  EXPECT_EQ(c.part1->external.path, tmp / "results");
  EXPECT_FALSE(c.part1->external.worldSpace);
  EXPECT_EQ(c.part1->toJson()["simulation"]["source"], "external");
  EXPECT_FALSE(parse(nlohmann::json::object()).part1->external.enabled());
  EXPECT_FALSE(parse(nlohmann::json::object()).part1->toJson()["simulation"].contains("source"));
  const BakeConfig w = parse({{"source", "external"},
                              {"path", "results"},
                              {"space", "world"},
                              {"units_per_metre", 100},
                              {"up_axis", "z"},
                              {"origin", {1, 2, 3}}});
  EXPECT_TRUE(w.part1->external.worldSpace);
  EXPECT_EQ(w.part1->external.upAxis, 'z');
  EXPECT_EQ(w.part1->external.origin, Vec3d(1, 2, 3));
  EXPECT_NE(errorFor({{"source", "houdini"}}).find("part1.simulation.source: 'houdini' is not one of solver, external"),
            std::string::npos);
  EXPECT_NE(errorFor({{"source", "external"}}).find("part1.simulation.path: is required"), std::string::npos);
  EXPECT_NE(errorFor({{"path", "results"}}).find("applies to \"source\": \"external\" only"), std::string::npos);
  EXPECT_NE(errorFor({{"source", "external"}, {"path", "nothing"}}).find("does not exist"), std::string::npos);
  EXPECT_NE(errorFor({{"source", "external"}, {"path", "results"}, {"up_axis", "z"}}).find("\"space\": \"world\" only"),
            std::string::npos);
  EXPECT_NE(errorFor({{"source", "external"}, {"path", "results"}, {"space", "world"}, {"up_axis", "x"}})
                .find("part1.simulation.up_axis"),
            std::string::npos);
  EXPECT_NE(errorFor({{"source", "external"}, {"path", "results"}, {"space", "world"}, {"origin", {1, 2}}})
                .find("part1.simulation.origin"),
            std::string::npos);
}

// FBX through assimp (Debian's assimp-testmodels box): read as a per-pose result in its own order.
TEST(ExternalSimulation, AnFbxPoseFileIsReadThroughAssimp) {
  const fs::path box = "/usr/share/assimp/models/FBX/box.fbx";
  if (!fs::exists(box)) GTEST_SKIP() << box << " is missing (Debian package assimp-testmodels)";
  const std::vector<io::ImportedMesh> meshes = io::importMeshes(box);
  ASSERT_EQ(meshes.size(), 1u);
  const test::TempDir tmp("test_external_fbx");
  fs::copy_file(box, tmp / "pose_000000.fbx");
  ExternalSimulationSettings es;
  es.path = tmp.path();
  const ExternalShapeSource src(es, meshes[0].positions, meshes[0].triangles, {3, 4}, 1);
  EXPECT_EQ(src.shape(0), meshes[0].positions);
  std::ofstream(tmp / "pose_000001.fbx") << "Kaydara FBX Binary  \x00 broken";
  const std::string e = test::errorOf([&] { src.shape(1); });
  EXPECT_NE(e.find("pose_000001.fbx"), std::string::npos) << e;
}
