// Quality levels: the ladder (default, JSON, metadata), the frame evaluator at a level, and the level
// planner (screen size, tolerance, budget, hold, fixed levels).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/level_planner.hpp"
#include "swish/runtime/quality_levels.hpp"

using namespace swish;
using namespace swish::runtime;

namespace {

Model modelWith(uint32_t k, uint32_t maps, uint64_t seed = 1) {
  Rng rng(test::testSeed(seed));
  test::RandomModelSpec spec;
  spec.meshComponents = k;
  spec.normalMaps = maps;
  return test::makeRandomModel(rng, spec);
}

QualityLadder measuredLadder(const std::vector<double>& meanMm) {
  QualityLadder l;
  for (size_t i = 0; i < meanMm.size(); ++i) {
    QualityLevel q;
    q.name = "L" + std::to_string(i);
    q.meshComponents = uint32_t(meanMm.size() - 1 - i);
    q.vertexMeanMm = meanMm[i];
    l.levels.push_back(q);
  }
  l.poses = 10;
  return l;
}

}  // namespace

TEST(QualityLadder, DefaultGoesFromFullToTheMeanShapeSkinned) {
  const Model m = modelWith(32, 4);
  const QualityLadder l = defaultLadder(m);
  ASSERT_EQ(l.size(), 5u);
  const std::vector<std::pair<uint32_t, bool>> expected = {{32, true}, {16, true}, {8, false}, {4, false}, {0, false}};
  for (size_t i = 0; i < l.size(); ++i) {
    EXPECT_EQ(l[i].meshComponents, expected[i].first) << i;
    EXPECT_EQ(l[i].normalMaps, expected[i].second) << i;
  }
  EXPECT_EQ(l[0].name, "full");
  EXPECT_EQ(l[4].name, "skinned");
  EXPECT_FALSE(l[4].needsNetwork());
  EXPECT_FALSE(l.measured());
  const QualityLadder noMaps = ladderOf(m, false);  // as run without the database: same components, no maps
  ASSERT_EQ(noMaps.size(), l.size());
  for (size_t i = 0; i < l.size(); ++i) {
    EXPECT_EQ(noMaps[i].meshComponents, l[i].meshComponents);
    EXPECT_FALSE(noMaps[i].normalMaps);
  }
  // Small K and no maps: no level repeats another.
  const QualityLadder small = defaultLadder(modelWith(3, 0));
  ASSERT_EQ(small.size(), 3u);  // 3, 3/2 = 1, then 3/4 = 3/8 = 0 once
  EXPECT_EQ(small[0].meshComponents, 3u);
  EXPECT_EQ(small[1].meshComponents, 1u);
  EXPECT_EQ(small[2].meshComponents, 0u);
  EXPECT_EQ(small[0].name, "full");
}

TEST(QualityLadder, RoundTripsThroughTheMetadataAndKeepsTheRest) {
  Model m = modelWith(16, 4);
  m.metadata = R"({"dataset_settings": {"x": 1}})";
  QualityLadder l = defaultLadder(m);
  l.levels[0].vertexMeanMm = 1.5;
  l.levels[1].vertexP95Mm = 4.25;
  l.levels[2].cpuUsPerCharacter = 12;
  l.poses = 140;
  l.measuredOn = "held-out poses";
  storeLadder(m, l);
  const nlohmann::json meta = nlohmann::json::parse(m.metadata);
  EXPECT_EQ(meta["dataset_settings"]["x"], 1);
  const QualityLadder back = ladderOf(m);
  ASSERT_EQ(back.size(), l.size());
  EXPECT_EQ(back.poses, 140u);
  EXPECT_EQ(back.measuredOn, "held-out poses");
  EXPECT_DOUBLE_EQ(back[0].vertexMeanMm, 1.5);
  EXPECT_DOUBLE_EQ(back[1].vertexP95Mm, 4.25);
  EXPECT_DOUBLE_EQ(back[2].cpuUsPerCharacter, 12);
  EXPECT_TRUE(std::isnan(back[3].vertexMeanMm));
  for (size_t i = 0; i < l.size(); ++i) EXPECT_EQ(back[i].name, l[i].name);
}

TEST(QualityLadder, RejectsLaddersTheModelCannotRun) {
  const Model m = modelWith(8, 0);
  const auto parse = [&](const char* text) { return ladderFromJson(nlohmann::json::parse(text), m, "ladder"); };
  EXPECT_NE(test::errorOf([&] {
              parse(R"({"levels": [{"name": "a", "mesh_components": 9, "normal_maps": false}]})");
            }).find("more than the model's 8"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              parse(R"({"levels": [{"name": "a", "mesh_components": 8, "normal_maps": true}]})");
            }).find("no normal-map database"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              parse(R"({"levels": [{"name": "a", "mesh_components": 4, "normal_maps": false},
                                   {"name": "b", "mesh_components": 8, "normal_maps": false}]})");
            }).find("costs more than the level before it"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { parse(R"({"levels": []})"); }).find("empty"), std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              parse(R"({"levels": [{"mesh_components": 4, "normal_maps": false}]})");
            }).find("levels[0].name"),
            std::string::npos);
}

TEST(QualityLevelsFrameEvaluator, LevelsTruncateWeightsSkipMapsAndTheNetwork) {
  const Model m = modelWith(12, 8, 7);
  const uint32_t n = 4;
  FrameEvaluator full(m, n), levelled(m, n);
  const QualityLadder ladder = defaultLadder(m);  // 12+maps, 6+maps, 3 flat, 1 flat, 0
  ASSERT_EQ(ladder.size(), 5u);
  levelled.setLevel(1, ladder[1]);
  levelled.setLevel(2, ladder[2]);
  levelled.setLevel(3, ladder[4]);
  Rng rng(test::testSeed(11));
  for (int f = 0; f < 3; ++f) {
    std::vector<Pose> poses;
    for (uint32_t c = 0; c < n; ++c) poses.push_back(test::makeRandomPose(rng, m.skeleton, 1.2f));
    const FrameOutput& a = full.evaluate(std::span<const Pose>(poses), 1.f / 30);
    const FrameOutput b = levelled.evaluate(std::span<const Pose>(poses), 1.f / 30);
    const size_t k = 12;
    const uint32_t kOf[n] = {12, 6, 3, 0};
    for (uint32_t c = 0; c < n; ++c)
      for (size_t i = 0; i < k; ++i) {
        const float expect = i < kOf[c] ? a.meshWeights[c * k + i] : 0.f;
        ASSERT_EQ(std::bit_cast<uint32_t>(b.meshWeights[c * k + i]), std::bit_cast<uint32_t>(expect))
            << "character " << c << " component " << i;
      }
    EXPECT_EQ(b.mapIndex[0], a.mapIndex[0]);
    EXPECT_EQ(b.mapIndex[1], a.mapIndex[1]);
    EXPECT_EQ(b.mapIndex[2], kNoMap);
    EXPECT_EQ(b.mapIndex[3], kNoMap);
    EXPECT_EQ(b.blendAlpha[2], 0.f);
    EXPECT_EQ(b.blendAlpha[0], a.blendAlpha[0]);
  }
  // Maps come back: the filter starts again without history.
  levelled.setLevel(2, ladder[0]);
  std::vector<Pose> poses(n, test::makeRandomPose(rng, m.skeleton));
  const FrameOutput& b = levelled.evaluate(std::span<const Pose>(poses), 1.f / 30);
  EXPECT_TRUE(b.blend[2].firstFrame);
  EXPECT_EQ(b.blendAlpha[2], 1.f);
  EXPECT_FALSE(b.blend[0].firstFrame);
  QualityLevel tooMany = ladder[0];
  tooMany.meshComponents = 13;
  EXPECT_NE(test::errorOf([&] { levelled.setLevel(0, tooMany); }).find("the model has 12"), std::string::npos);
  EXPECT_NE(test::errorOf([&] { levelled.setLevel(4, ladder[0]); }).find("character 4 of 4"), std::string::npos);
}

TEST(LevelPlannerView, ProjectsSizeByDistance) {
  LevelCamera cam;
  cam.position = {0, 1, -10};
  cam.target = {0, 1, 0};
  cam.verticalFovDegrees = 90;  // focal length = half the image height
  cam.imageHeightPixels = 1000;
  const CharacterView near = viewOf(cam, {0, 1, 0});
  EXPECT_NEAR(near.distance, 10.0, 1e-9);
  EXPECT_NEAR(near.pixelsPerMm, 500.0 / 10000.0, 1e-9);
  EXPECT_NEAR(near.heightPixels, 90.0, 1e-6);
  EXPECT_TRUE(near.inView);
  const CharacterView far = viewOf(cam, {0, 1, 10});
  EXPECT_NEAR(far.heightPixels, 45.0, 1e-6);
  EXPECT_NEAR(far.weight() / near.weight(), 0.25, 1e-9);
  EXPECT_FALSE(viewOf(cam, {0, 1, -20}).inView);  // behind the camera
  EXPECT_FALSE(viewOf(cam, {100, 1, 0}).inView);  // far off to the side
}

TEST(LevelPlanner, ToleranceChoosesTheCheapestLevelWithinItOnScreen) {
  const QualityLadder ladder = measuredLadder({1.0, 2.0, 8.0, 30.0});
  LevelPlannerSettings s;
  s.camera.position = {0, 1, -10};
  s.camera.target = {0, 1, 0};
  s.camera.verticalFovDegrees = 90;
  s.camera.imageHeightPixels = 1000;
  s.tolerancePixels = 0.5;  // 0.05 px per mm at 10 m: 10 mm fit; 0.025 at 20 m: 20 mm fit
  LevelPlanner planner({&ladder, &ladder, &ladder, &ladder}, {}, s);
  const std::vector<Eigen::Vector3d> roots = {{0, 1, 0}, {0, 1, 10}, {0, 1, -9}, {0, 1, -30}};
  const PlannedLevels& p = planner.plan(0, roots);
  EXPECT_EQ(p.characters[0].level, 2u);  // 8 mm * 0.05 = 0.4 px
  EXPECT_EQ(p.characters[1].level, 2u);  // 30 mm * 0.025 = 0.75 px: too much
  EXPECT_EQ(p.characters[2].level, 0u);  // 1 m away: 2 mm would be a whole pixel
  EXPECT_NE(p.characters[0].reason.find("within"), std::string::npos);
  EXPECT_EQ(p.characters[3].level, 3u);  // behind the camera
  EXPECT_EQ(p.characters[3].reason, "out of view");
  // Neither tolerance nor budget: everyone at full quality, in view or not (the replay before levels).
  LevelPlannerSettings none = s;
  none.tolerancePixels.reset();
  LevelPlanner plain({&ladder, &ladder, &ladder, &ladder}, {}, none);
  for (const LevelChoice& c : plain.plan(0, roots).characters) EXPECT_EQ(c.level, 0u);
}

TEST(LevelPlanner, BudgetStepsDownSmallAndFarCharactersFirst) {
  const QualityLadder ladder = measuredLadder({1.0, 2.0, 4.0, 20.0});
  LevelPlannerSettings s;
  s.camera.position = {0, 1, -10};
  s.camera.target = {0, 1, 0};
  s.frameBudgetMs = 5.0;
  s.holdFrames = 3;
  LevelPlanner planner({&ladder, &ladder}, {}, s);
  LevelCosts costs;
  costs.msPerCharacter = {{4, 2, 1, 0.5}, {4, 2, 1, 0.5}};
  planner.setCosts(costs);
  const std::vector<Eigen::Vector3d> roots = {{0, 1, 0}, {0, 1, 30}};  // near, far
  const PlannedLevels& p = planner.plan(0, roots);
  EXPECT_LE(p.predictedMs, 5.0);
  EXPECT_FALSE(p.overBudget);
  EXPECT_LT(p.characters[0].level, p.characters[1].level) << "the near character keeps more quality";
  EXPECT_GT(p.weightedErrorMm, p.fullErrorMm);
  EXPECT_NEAR(p.fullErrorMm, 1.0, 1e-12);
  // The GPU runs 4x slower than calibrated: the same budget buys less.
  LevelPlanner slow({&ladder, &ladder}, {}, s);
  slow.setCosts(costs);
  slow.setCostScale(4.0);
  const PlannedLevels& ps = slow.plan(0, roots);
  EXPECT_NEAR(ps.predictedMs, 4.0 * ps.unscaledMs, 1e-12);
  EXPECT_FALSE(ps.overBudget);
  EXPECT_EQ(ps.characters[0].level, 3u);  // 2 x 0.5 ms x 4 = 4 ms is the only mix within 5 ms
  EXPECT_EQ(ps.characters[1].level, 3u);
  EXPECT_NEAR(ps.predictedMs, 4.0, 1e-12);
  EXPECT_NE(test::errorOf([&] { slow.setCostScale(0.0); }).find("positive"), std::string::npos);
  // A budget nothing can meet: every character at its cheapest, and said so.
  LevelPlannerSettings tight = s;
  tight.frameBudgetMs = 0.1;
  LevelPlanner t({&ladder, &ladder}, {}, tight);
  t.setCosts(costs);
  const PlannedLevels& q = t.plan(0, roots);
  EXPECT_TRUE(q.overBudget);
  EXPECT_EQ(q.characters[0].level, 3u);
  EXPECT_EQ(q.characters[1].level, 3u);
}

TEST(LevelPlanner, HoldsALevelAndKeepsFixedOnes) {
  const QualityLadder ladder = measuredLadder({1.0, 2.0, 4.0, 20.0});
  LevelPlannerSettings s;
  s.camera.position = {0, 1, -10};
  s.camera.target = {0, 1, 0};
  s.camera.verticalFovDegrees = 90;
  s.camera.imageHeightPixels = 1000;
  s.tolerancePixels = 0.5;
  s.holdFrames = 10;
  LevelPlanner planner({&ladder, &ladder}, {std::nullopt, 1u}, s);
  std::vector<Eigen::Vector3d> roots = {{0, 1, 90}, {0, 1, 90}};  // 100 m: 20 mm is 0.1 px
  EXPECT_EQ(planner.plan(0, roots).characters[0].level, 3u);
  EXPECT_EQ(planner.last().characters[1].level, 1u);
  roots[0] = {0, 1, 0};  // steps close: the first frame's assignment was no change, so it follows at once
  EXPECT_EQ(planner.plan(1, roots).characters[0].level, 2u);
  EXPECT_TRUE(planner.last().characters[0].changed);
  roots[0] = {0, 1, 90};  // and back: held until frame 11
  for (uint64_t f = 2; f < 11; ++f) {
    const PlannedLevels& p = planner.plan(f, roots);
    EXPECT_EQ(p.characters[0].level, 2u) << f;
    EXPECT_FALSE(p.characters[0].changed);
    EXPECT_NE(p.characters[0].reason.find("held"), std::string::npos);
    EXPECT_EQ(p.characters[1].level, 1u);
  }
  const PlannedLevels& p = planner.plan(11, roots);
  EXPECT_EQ(p.characters[0].level, 3u);
  EXPECT_TRUE(p.characters[0].changed);
  EXPECT_EQ(p.characters[1].reason, "fixed (the scene's level or --level)");
  EXPECT_NE(test::errorOf([&] { LevelPlanner bad({&ladder}, {7u}, s); }).find("level 7"), std::string::npos);
  EXPECT_EQ(levelIndex(ladder, "L2", "x"), 2u);
  EXPECT_EQ(levelIndex(ladder, "3", "x"), 3u);
  EXPECT_NE(test::errorOf([&] { levelIndex(ladder, "k999", "scene level"); }).find("0 L0, 1 L1"), std::string::npos);
}
