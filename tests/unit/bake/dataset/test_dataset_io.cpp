// The dataset folder: round trip, resumability, and clear errors for corrupt or mismatched files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

Character makeCharacter(Rng& rng) {
  test::RandomModelSpec spec;
  spec.vertices = 60;
  const Model m = test::makeRandomModel(rng, spec);
  Character c;
  c.name = "random";
  c.skeleton = m.skeleton;
  c.garment = m.gameMesh;
  c.body = m.gameMesh;
  return c;
}

DatasetPose makePose(Rng& rng, const Character& c, uint32_t id, uint32_t mapSize = 12) {
  DatasetPose p;
  p.id = id;
  p.pose = test::makeRandomPose(rng, c.skeleton);
  p.pose.rootTranslation = Vec3f(0.1f, 0.2f, float(id));
  const auto mats = c.skeleton.skinningMatrices(p.pose);
  p.gameMeshPreSkin = c.garment.positions + Points3f::Constant(c.garment.positions.rows(), 3, 0.001f * float(id));
  p.gameMeshWorld = skinPositions(p.gameMeshPreSkin, c.garment.skin, mats);
  p.normalMap.width = p.normalMap.height = mapSize;
  p.normalMap.xy.resize(mapSize * mapSize * 2);
  for (float& v : p.normalMap.xy) v = float(rng.uniform(-0.7, 0.7));
  p.residuals = {0.01f * float(id), 0.002f, id % 2 == 0, int(100 + id), 1.25 * id};
  return p;
}

void expectErrorMentioning(const std::function<void()>& f, const std::string& needle,
                           std::source_location where = std::source_location::current()) {
  const std::string e = test::errorOf(f, where);
  EXPECT_NE(e.find(needle), std::string::npos) << e;
}

}  // namespace

TEST(DatasetIo, RoundTripsEverythingAndResumes) {
  Rng rng(test::testSeed(501));
  const Character c = makeCharacter(rng);
  const test::TempDir tmp("test_dataset_roundtrip");
  const fs::path dir = tmp / "dataset";
  std::vector<DatasetPose> poses;
  for (uint32_t id : {0u, 3u, 7u}) poses.push_back(makePose(rng, c, id));
  {
    DatasetWriter w(dir, c, {1, 2}, {{"smoothing", 0.5}});
    for (const auto& p : poses) {
      EXPECT_FALSE(w.hasPose(p.id));
      w.writePose(p);
      EXPECT_TRUE(w.hasPose(p.id));
    }
    w.writeManifest({{5, "did not converge"}}, {{"clip", "01_01.bvh"}});
  }
  // Reopening the folder for the same character resumes: finished poses are seen as done.
  DatasetWriter again(dir, c, {1, 2}, {{"smoothing", 0.5}});
  EXPECT_TRUE(again.hasPose(3));
  EXPECT_FALSE(again.hasPose(5));

  const Dataset d = readDataset(dir);
  EXPECT_EQ(d.inputJoints, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(d.settings.at("smoothing").get<double>(), 0.5);
  EXPECT_EQ(d.character.name, "random");
  EXPECT_EQ(d.character.garment.positions, c.garment.positions);
  EXPECT_EQ(d.character.garment.skin.weights, c.garment.skin.weights);
  EXPECT_EQ(d.character.skeleton.size(), c.skeleton.size());
  ASSERT_EQ(d.poses.size(), poses.size());
  for (size_t k = 0; k < poses.size(); ++k) {
    const DatasetPose &a = poses[k], &b = d.poses[k];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.gameMeshWorld, b.gameMeshWorld);
    EXPECT_EQ(a.gameMeshPreSkin, b.gameMeshPreSkin);
    EXPECT_EQ(a.pose.rootTranslation, b.pose.rootTranslation);
    for (size_t j = 0; j < a.pose.local.size(); ++j) EXPECT_EQ(a.pose.local[j].coeffs(), b.pose.local[j].coeffs());
    EXPECT_EQ(a.residuals.maxConstraintViolation, b.residuals.maxConstraintViolation);
    EXPECT_EQ(a.residuals.converged, b.residuals.converged);
    EXPECT_EQ(a.residuals.iterations, b.residuals.iterations);
    EXPECT_EQ(a.residuals.seconds, b.residuals.seconds);
    ASSERT_EQ(b.normalMap.xy.size(), a.normalMap.xy.size());
    for (size_t i = 0; i < a.normalMap.xy.size(); ++i) EXPECT_NEAR(a.normalMap.xy[i], b.normalMap.xy[i], 2.f / 65535.f);
  }
  // The manifest lists the poses with residuals and the failed pose with its reason.
  std::ifstream in(dir / "manifest.json");
  const auto m = nlohmann::json::parse(in);
  EXPECT_EQ(m.at("poses").size(), 3u);
  EXPECT_EQ(m.at("poses")[1].at("residuals").at("iterations").get<int>(), 103);
  EXPECT_EQ(m.at("failedPoses")[0].at("reason").get<std::string>(), "did not converge");
  EXPECT_EQ(m.at("normalMap").at("bitDepth").get<int>(), 16);
}

TEST(DatasetIo, CorruptOrMismatchedFilesGiveErrorsNamingTheFile) {
  Rng rng(test::testSeed(502));
  const Character c = makeCharacter(rng);
  const test::TempDir tmp("test_dataset_corrupt");
  const fs::path dir = tmp / "dataset";
  DatasetWriter w(dir, c, {0}, nlohmann::json::object(), 8);
  w.writePose(makePose(rng, c, 1));
  w.writePose(makePose(rng, c, 2));
  w.writeManifest();
  ASSERT_NO_THROW(readDataset(dir));

  // A flipped byte in a pose file.
  const fs::path pose = datasetPosePath(dir, 2);
  std::vector<char> bytes(fs::file_size(pose));
  std::ifstream(pose, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
  std::vector<char> flipped = bytes;
  flipped[100] ^= 0x10;
  std::ofstream(pose, std::ios::binary).write(flipped.data(), std::streamsize(flipped.size()));
  expectErrorMentioning([&] { readDataset(dir); }, "pose_00002.bin");
  // Truncated.
  std::ofstream(pose, std::ios::binary).write(bytes.data(), 40);
  expectErrorMentioning([&] { readDataset(dir); }, "pose_00002.bin");
  // Missing.
  fs::remove(pose);
  expectErrorMentioning([&] { readDataset(dir); }, "pose_00002.bin");
  std::ofstream(pose, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_NO_THROW(readDataset(dir));

  // A normal map that is not a PNG.
  const fs::path png = datasetNormalMapPath(dir, 1);
  const auto pngBytes = fs::file_size(png);
  fs::resize_file(png, pngBytes / 2);
  expectErrorMentioning([&] { readDataset(dir); }, "pose_00001.png");
  w.writePose(makePose(rng, c, 1));

  // Manifest: garbage, wrong format, missing entries.
  const fs::path manifest = dir / "manifest.json";
  std::ofstream(manifest) << "{ not json";
  expectErrorMentioning([&] { readDataset(dir); }, "manifest.json");
  std::ofstream(manifest) << R"({"format": "something-else", "version": 1})";
  expectErrorMentioning([&] { readDataset(dir); }, "manifest.json");
  std::ofstream(manifest) << R"({"format": "swish-dataset", "version": 1})";
  expectErrorMentioning([&] { readDataset(dir); }, "manifest.json");
  w.writeManifest();
  ASSERT_NO_THROW(readDataset(dir));

  // A corrupt character file.
  const fs::path charFile = dir / "character.bin";
  fs::resize_file(charFile, fs::file_size(charFile) - 9);
  expectErrorMentioning([&] { readDataset(dir); }, "character.bin");

  // Reopening the folder for another character is refused.
  Rng other(test::testSeed(503));
  expectErrorMentioning([&] { DatasetWriter(dir, makeCharacter(other), {0}, {}); }, "character.bin");
}

TEST(DatasetIo, WriterRejectsPosesThatDoNotFitTheCharacter) {
  Rng rng(test::testSeed(504));
  const Character c = makeCharacter(rng);
  const test::TempDir tmp("test_dataset_reject");
  const fs::path dir = tmp / "dataset";
  DatasetWriter w(dir, c, {0}, {});
  DatasetPose p = makePose(rng, c, 4);
  p.gameMeshWorld.conservativeResize(p.gameMeshWorld.rows() - 1, 3);
  EXPECT_THROW(w.writePose(p), Error);
  p = makePose(rng, c, 4);
  p.pose.local.pop_back();
  EXPECT_THROW(w.writePose(p), Error);
  p = makePose(rng, c, 4);
  p.gameMeshPreSkin(0, 0) = std::nanf("");
  EXPECT_THROW(w.writePose(p), Error);
  p = makePose(rng, c, 4);
  p.normalMap.xy.pop_back();
  EXPECT_THROW(w.writePose(p), Error);
  EXPECT_FALSE(w.hasPose(4));
  EXPECT_THROW(DatasetWriter(dir, c, {999}, {}), Error);
}
