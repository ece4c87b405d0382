// Simulations made elsewhere: the BVH transition clip re-imports (assimp) to the same rotations; the
// OBJ reader maps results by vertex order and rejects bad files with file:line errors.
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/cloth/external_simulation.hpp"
#include "swish/core/error.hpp"

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
