// The replay scene file: a valid scene parses with its defaults and resolved paths; every kind of bad
// input (unknown key, wrong type, out-of-range value, missing file, invalid JSON) is an Error naming the
// scene file, the JSON path and the problem. The shipped default scene parses.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/scene_file.hpp"

namespace {

using nlohmann::json;
using swish::runtime::parseScene;
namespace fs = std::filesystem;

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir_ / "a.swish") << "not really a model, but it exists";
    std::ofstream(dir_ / "walk.bvh") << "HIERARCHY";
  }
  fs::path source() const { return dir_ / "scene.json"; }

  json valid() const {
    return json::parse(R"({
      "frames": {"count": 10, "rate": 24},
      "outputs": {"render": true, "directory": "out"},
      "characters": [
        {"name": "a", "model": "a.swish", "animation": {"file": "walk.bvh", "timeOffset": 0.5}},
        {"name": "b", "model": "default", "animation": {"file": "walk.bvh", "speed": 2},
         "placement": {"translation": [10000, 0, 5], "yawDegrees": 90}, "visible": false}
      ]})");
  }
  // The message of the Error parseScene throws for `j` (fails the test if it does not throw).
  std::string errorOf(const json& j, std::source_location where = std::source_location::current()) const {
    return swish::test::errorOf([&] { parseScene(j, source()); }, where);
  }
  const swish::test::TempDir tmp_{"scene_test"};
  const fs::path dir_ = tmp_.path();
};

TEST_F(SceneFileTest, ValidSceneParsesWithDefaultsAndResolvedPaths) {
  const auto s = parseScene(valid(), source());
  EXPECT_EQ(s.name, "scene");
  EXPECT_EQ(s.firstFrame, 0u);
  EXPECT_EQ(s.frameCount, 10u);
  EXPECT_DOUBLE_EQ(s.framesPerSecond, 24.0);
  ASSERT_EQ(s.characters.size(), 2u);
  EXPECT_EQ(fs::path(s.characters[0].model), dir_ / "a.swish");
  EXPECT_EQ(s.characters[1].model, "default");
  EXPECT_EQ(s.characters[0].clip->file, dir_ / "walk.bvh");
  EXPECT_DOUBLE_EQ(s.characters[0].clip->timeOffsetSeconds, 0.5);
  EXPECT_DOUBLE_EQ(s.characters[1].clip->speed, 2.0);
  EXPECT_DOUBLE_EQ(s.characters[1].placement.translation.x(), 10000.0);
  EXPECT_FALSE(s.characters[1].visible);
  EXPECT_TRUE(s.onScreen(0));
  EXPECT_FALSE(s.onScreen(1));
  EXPECT_EQ(s.outputs.directory, dir_ / "out");
  EXPECT_TRUE(s.outputs.render);
  EXPECT_FALSE(s.outputs.normalMaps);
  EXPECT_FALSE(s.body.pushOut) << "the body is drawn as it is unless the scene asks";
  EXPECT_FALSE(s.body.hideCovered);
  // Round trip through sceneToJson keeps what matters.
  const auto again = parseScene(swish::runtime::sceneToJson(s), source());
  EXPECT_EQ(again.characters[1].placement.yawDegrees, 90.0);
  EXPECT_EQ(again.characters[0].model, s.characters[0].model);

  // The body under the garment: push-out and hidden covered triangles when the scene asks.
  json j = valid();
  j["body"] = {{"pushOut", true}, {"hideCovered", true}};
  const auto b = parseScene(j, source());
  EXPECT_TRUE(b.body.pushOut);
  EXPECT_TRUE(b.body.hideCovered);
  const auto b2 = parseScene(swish::runtime::sceneToJson(b), source());
  EXPECT_TRUE(b2.body.pushOut && b2.body.hideCovered);
  j["body"]["hide"] = true;
  EXPECT_NE(errorOf(j).find("body.hide: unknown key"), std::string::npos);
  j["body"] = {{"pushOut", 1}};
  EXPECT_NE(errorOf(j).find("body.pushOut: must be true or false"), std::string::npos);
}

TEST_F(SceneFileTest, UnknownKeyNamesFileAndPath) {
  json j = valid();
  j["characters"][1]["colour"] = "red";
  const std::string e = errorOf(j);
  EXPECT_NE(e.find(source().string()), std::string::npos) << e;
  EXPECT_NE(e.find("characters[1].colour"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  j = valid();
  j["outputs"]["gltf"] = true;
  EXPECT_NE(errorOf(j).find("outputs.gltf: unknown key"), std::string::npos);
}

TEST_F(SceneFileTest, WrongTypesAreNamed) {
  json j = valid();
  j["frames"]["count"] = "ten";
  EXPECT_NE(errorOf(j).find("frames.count: must be an integer"), std::string::npos);
  j = valid();
  j["characters"][0]["placement"] = {{"translation", {1, 2}}};
  EXPECT_NE(errorOf(j).find("characters[0].placement.translation: must be an array of 3 numbers"), std::string::npos);
  j = valid();
  j["characters"][1]["visible"] = 1;
  EXPECT_NE(errorOf(j).find("characters[1].visible: must be true or false"), std::string::npos);
  j = valid();
  j["characters"] = json::object();
  EXPECT_NE(errorOf(j).find("characters: must be an array"), std::string::npos);
}

TEST_F(SceneFileTest, OutOfRangeValuesAreNamed) {
  json j = valid();
  j["frames"]["count"] = 0;
  EXPECT_NE(errorOf(j).find("frames.count: must be 1 to"), std::string::npos);
  j = valid();
  j["frames"]["rate"] = -30;
  EXPECT_NE(errorOf(j).find("frames.rate"), std::string::npos);
  j = valid();
  j["characters"][0]["animation"]["speed"] = 0;
  EXPECT_NE(errorOf(j).find("characters[0].animation.speed: must be in (0, 100]"), std::string::npos);
  j = valid();
  j["characters"][0]["placement"] = {{"translation", {0, 0, 1e9}}};
  EXPECT_NE(errorOf(j).find("characters[0].placement.translation: is beyond 1e7 m"), std::string::npos);
  j = valid();
  j["cullDistance"] = 0;
  EXPECT_NE(errorOf(j).find("cullDistance: must be a positive"), std::string::npos);
  j = valid();
  j["outputs"]["gpuCheckEvery"] = 0;
  EXPECT_NE(errorOf(j).find("outputs.gpuCheckEvery"), std::string::npos);
}

TEST_F(SceneFileTest, MissingFilesAndStructureAreNamed) {
  json j = valid();
  j["characters"][0]["model"] = "nope.swish";
  std::string e = errorOf(j);
  EXPECT_NE(e.find("characters[0].model: file '"), std::string::npos) << e;
  EXPECT_NE(e.find("nope.swish' does not exist"), std::string::npos) << e;
  j = valid();
  j["characters"][1]["animation"]["file"] = "gone.bvh";
  EXPECT_NE(errorOf(j).find("characters[1].animation.file: file"), std::string::npos);
  j = valid();
  j["characters"][0]["poseStream"] = "walk.bvh";
  EXPECT_NE(errorOf(j).find("characters[0]: needs exactly one of"), std::string::npos);
  j = valid();
  j["characters"][1]["name"] = "a";
  EXPECT_NE(errorOf(j).find("characters[1].name: 'a' is used by another character"), std::string::npos);
  j = valid();
  j.erase("frames");
  EXPECT_NE(errorOf(j).find("frames: is required"), std::string::npos);
  j = valid();
  j["characters"] = json::array();
  EXPECT_NE(errorOf(j).find("at least one character"), std::string::npos);
  // Files are not looked at when asked not to.
  j = valid();
  j["characters"][0]["model"] = "nope.swish";
  EXPECT_NO_THROW(parseScene(j, source(), /*checkFiles=*/false));
}

TEST_F(SceneFileTest, InvalidJsonAndMissingSceneFile) {
  std::ofstream(source()) << "{ \"frames\": { \"count\": 3, }";
  try {
    swish::runtime::loadScene(source());
    ADD_FAILURE() << "no error";
  } catch (const swish::Error& e) {
    EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos) << e.what();
  }
  EXPECT_THROW(swish::runtime::loadScene(dir_ / "absent.json"), swish::Error);
}

TEST_F(SceneFileTest, AJointMapIsInlineOrAFile) {
  json j = valid();
  j["characters"][0]["animation"]["jointMap"] = {{"hip", "Hips"}, {"chest", {"Spine", "Spine1"}}};
  std::ofstream(dir_ / "daz.json") << R"({"abdomen": "LowerBack"})";
  j["characters"][1]["animation"]["jointMap"] = "daz.json";
  const auto s = parseScene(j, source());
  EXPECT_EQ(s.characters[0].clip->jointMap["hip"], "Hips");
  EXPECT_TRUE(s.characters[0].clip->jointMapFile.empty());
  EXPECT_EQ(s.characters[1].clip->jointMapFile, dir_ / "daz.json");
  EXPECT_EQ(s.characters[1].clip->jointMap["abdomen"], "LowerBack");
  EXPECT_EQ(swish::runtime::sceneToJson(s)["characters"][1]["animation"]["jointMap"], (dir_ / "daz.json").string());

  j["characters"][1]["animation"]["jointMap"] = "none.json";
  EXPECT_NE(errorOf(j).find("characters[1].animation.jointMap"), std::string::npos) << errorOf(j);
  j["characters"][1]["animation"]["jointMap"] = 3;
  EXPECT_NE(errorOf(j).find("must be a joint map object"), std::string::npos) << errorOf(j);
  std::ofstream(dir_ / "list.json") << "[1, 2]";
  j["characters"][1]["animation"]["jointMap"] = "list.json";
  EXPECT_NE(errorOf(j).find("the joint map must be a JSON object"), std::string::npos) << errorOf(j);
}

TEST(DefaultScene, FootballPlayParses) {
  const fs::path file = swish::test::sourceDir() / "assets/scenes/football.json";
  const bool haveClips =
      fs::exists(swish::test::debianMocap("01_01.bvh")) && fs::exists(swish::test::debianMocap("01_03.bvh"));
  const auto s = swish::runtime::loadScene(file, /*checkFiles=*/haveClips);
  EXPECT_EQ(s.characters.size(), 22u);
  size_t clip01 = 0;
  for (size_t i = 0; i < s.characters.size(); ++i) {
    EXPECT_EQ(s.characters[i].model, "default");
    EXPECT_TRUE(s.onScreen(i));
    clip01 += s.characters[i].clip->file.filename() == "01_01.bvh";
  }
  EXPECT_EQ(clip01, 11u);  // both clips are used
  // A game scene: the garment kept off the body, the skin under it not drawn (issue 19).
  EXPECT_TRUE(s.body.pushOut);
  EXPECT_TRUE(s.body.hideCovered);
  // Offsets differ, so no two characters play the same frames.
  for (size_t i = 1; i < s.characters.size(); ++i)
    EXPECT_NE(s.characters[i].clip->timeOffsetSeconds, s.characters[i - 1].clip->timeOffsetSeconds);
}

}  // namespace

TEST_F(SceneFileTest, CameraLevelsAndAFixedLevel) {
  json j = valid();
  j["camera"] = {{"position", {0, 12, -45}}, {"target", {0, 1, 0}}, {"fovDegrees", 40}, {"imageHeight", 720}};
  j["levels"] = {{"frameBudgetMs", 6.5}, {"tolerancePixels", 0.5}, {"holdSeconds", 2}};
  j["characters"][0]["level"] = "k64";
  j["characters"][1]["level"] = 3;
  const auto s = parseScene(j, source());
  ASSERT_TRUE(s.cameraTarget.has_value());
  EXPECT_DOUBLE_EQ(s.cameraTarget->y(), 1.0);
  EXPECT_DOUBLE_EQ(s.cameraFovDegrees, 40.0);
  EXPECT_DOUBLE_EQ(s.imageHeightPixels, 720.0);
  EXPECT_DOUBLE_EQ(*s.levels.frameBudgetMs, 6.5);
  EXPECT_DOUBLE_EQ(*s.levels.tolerancePixels, 0.5);
  EXPECT_DOUBLE_EQ(s.levels.holdSeconds, 2.0);
  EXPECT_EQ(s.characters[0].level, "k64");
  EXPECT_EQ(s.characters[1].level, "3");
  const auto settings = s.levelPlannerSettings();
  EXPECT_DOUBLE_EQ(*settings.frameBudgetMs, 6.5);
  EXPECT_EQ(settings.holdFrames, 48u);                                // 2 s at 24 fps
  EXPECT_DOUBLE_EQ(*s.levelPlannerSettings(3.0).frameBudgetMs, 3.0);  // a budget given here replaces the scene's
  EXPECT_DOUBLE_EQ(*s.levelPlannerSettings(3.0).tolerancePixels, 0.5);
  const auto cam = s.levelCamera();
  EXPECT_DOUBLE_EQ(cam.verticalFovDegrees, 40.0);
  EXPECT_DOUBLE_EQ(cam.target.y(), 1.0);
  const auto again = parseScene(swish::runtime::sceneToJson(s), source());
  EXPECT_DOUBLE_EQ(*again.levels.frameBudgetMs, 6.5);
  EXPECT_EQ(again.characters[1].level, "3");
  EXPECT_DOUBLE_EQ(again.cameraFovDegrees, 40.0);
  // Without a target the camera looks at the characters' mean, 1 m up.
  const auto plain = parseScene(valid(), source()).levelCamera();
  EXPECT_DOUBLE_EQ(plain.target.x(), 5000.0);
  EXPECT_DOUBLE_EQ(plain.target.y(), 1.0);

  json bad = j;
  bad["levels"]["frameBudgetMs"] = -1;
  EXPECT_NE(errorOf(bad).find("levels.frameBudgetMs"), std::string::npos);
  bad = j;
  bad["levels"]["budget"] = 1;
  EXPECT_NE(errorOf(bad).find("levels.budget: unknown key"), std::string::npos);
  bad = j;
  bad["camera"]["fovDegrees"] = 179;
  EXPECT_NE(errorOf(bad).find("camera.fovDegrees"), std::string::npos);
  bad = j;
  bad["camera"]["target"] = {0, 12, -45};
  EXPECT_NE(errorOf(bad).find("camera.target: must differ from the position"), std::string::npos);
  bad = j;
  bad["characters"][0]["level"] = "";
  EXPECT_NE(errorOf(bad).find("characters[0].level"), std::string::npos);
}
