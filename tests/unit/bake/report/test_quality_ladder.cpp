// The quality ladder measured (bake/report/quality_ladder.hpp) on small random models whose truth is
// made by hand: a truth in the span of the model's own prediction (error 0 at full, the known truncation
// of the dropped components below it, the flat map's known angle), a truth the bake's evaluation also
// measures (the full level is its total, the skinned level its mean-shape baseline, to the bit), the
// monotonicity check, the CPU timing and the errors on bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "support/error_message.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/bake/compression/normal_map_pca.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/report/quality_ladder.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/nearest_code.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;
using runtime::QualityLadder;
using runtime::QualityLevel;

namespace {

test::RandomModelSpec smallSpec() {
  test::RandomModelSpec s;
  s.vertices = 60;
  s.meshComponents = 8;
  s.normalMaps = 5;
  s.codeDims = 3;
  s.mapSize = 8;
  s.noveltyCentres = 6;  // the guard clamps and blends: the path under test includes it
  return s;
}

// The run time's mesh weights and normal code of a pose: Theta -> MLP -> guard (what the ladder uses).
std::vector<float> runtimeLambda(const Model& m, const Pose& pose) {
  const runtime::MlpEvaluator mlp(m);
  const runtime::NoveltyGuardEvaluator guard(m);
  const std::vector<float> theta = runtime::computeTheta(m.inputJoints, pose.local);
  std::vector<float> lambda(size_t(mlp.outputSize()));
  mlp.evaluate(theta, lambda);
  guard.apply(guard.measureOne(theta), std::span<float>(lambda.data(), size_t(m.meshComponents())));
  return lambda;
}

// Linear part of vertex v's blended skinning transform.
Eigen::Matrix3d blendedLinear(const Model& m, const std::vector<Mat4f>& mats, size_t v) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  const uint32_t inf = m.gameMesh.skin.influences;
  for (uint32_t i = 0; i < inf; ++i) {
    const float w = m.gameMesh.skin.weights[v * inf + i];
    a += double(w) * mats[m.gameMesh.skin.joints[v * inf + i]].topLeftCorner<3, 3>().cast<double>();
  }
  return a;
}

struct ExpectedError {
  double mean = 0, max = 0;
};

}  // namespace

// Truth = the model's own full prediction (mean + basis x weights, skinned). Then the full level's error
// is 0 (float round-off only), a level with k components misses exactly the skinned sum of the dropped
// components, basis(:, k..K) x w(k..K), per vertex, and the mean shape misses all of them. The truth's
// normal map is the database map the predicted code selects (its VQ decode): map levels 0; levels
// without maps shade with the flat map, whose angle to a texel (x, y, z) is acos(z).
TEST(QualityLadder, TruthInTheModelsSpanGivesZeroAtFullAndTheDroppedComponentsBelow) {
  SWISH_TEST_SEED_SCOPE(seed, 2101);
  Rng rng(seed);
  const Model m = test::makeRandomModel(rng, smallSpec());
  const int K = m.meshComponents();
  const size_t n = m.gameMesh.vertexCount();
  const runtime::NearestCodeSearch search(m.normalMaps.keys);
  std::vector<DatasetPose> poses(10);
  std::vector<std::vector<float>> lambdas;
  for (uint32_t i = 0; i < poses.size(); ++i) {
    DatasetPose& p = poses[i];
    p.id = i;
    p.pose = test::makeRandomPose(rng, m.skeleton, 0.6f);
    const std::vector<float> lambda = runtimeLambda(m, p.pose);
    lambdas.push_back(lambda);
    const Eigen::VectorXd w = Eigen::Map<const VecXf>(lambda.data(), K).cast<double>();
    const Eigen::VectorXd pre = m.meshPca.mean.cast<double>() + m.meshPca.basis.cast<double>() * w;
    const Points3f preF =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(pre.data(), Eigen::Index(n), 3)
            .cast<float>();
    p.gameMeshWorld = skinPositions(preF, m.gameMesh.skin, m.skeleton.skinningMatrices(p.pose));
    const uint32_t selected = search.find(std::span<const float>(lambda.data() + K, size_t(m.normalCodeDims()))).index;
    p.normalMap = decodeVqMap(m.normalMaps, selected);
  }
  std::vector<const DatasetPose*> ptrs;
  for (const auto& p : poses) ptrs.push_back(&p);

  QualityLadder ladder = runtime::defaultLadder(m);
  ASSERT_EQ(ladder.size(), 5u);  // K = 8: full (maps), k4 (maps), k2-flat, k1-flat, skinned
  const QualityLadder measured = measureLadder(m, ptrs, ladder, "hand-made poses");
  EXPECT_EQ(measured.poses, 10u);
  EXPECT_EQ(measured.measuredOn, "hand-made poses");
  EXPECT_TRUE(std::isnan(measured.levels[0].cpuUsPerCharacter));  // not timed here

  for (size_t li = 0; li < measured.size(); ++li) {
    const QualityLevel& l = measured.levels[li];
    SCOPED_TRACE("level " + l.name);
    // Expected vertex error: the dropped components, through the blended skinning's linear part.
    ExpectedError e;
    for (size_t pi = 0; pi < poses.size(); ++pi) {
      const auto mats = m.skeleton.skinningMatrices(poses[pi].pose);
      for (size_t v = 0; v < n; ++v) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        for (int k = int(l.meshComponents); k < K; ++k)
          for (int a = 0; a < 3; ++a)
            d[a] += double(m.meshPca.basis(Eigen::Index(3 * v + size_t(a)), k)) * double(lambdas[pi][size_t(k)]);
        const double mm = 1000.0 * (blendedLinear(m, mats, v) * d).norm();
        e.mean += mm / double(n * poses.size());
        e.max = std::max(e.max, mm);
      }
    }
    if (l.meshComponents == uint32_t(K)) {
      EXPECT_LT(l.vertexMaxMm, 1e-3);  // float round-off of a shape of a few cm
    } else {
      EXPECT_GT(e.mean, 0.05);  // something is dropped
      EXPECT_NEAR(l.vertexMeanMm, e.mean, 1e-3 + 1e-4 * e.mean);
      EXPECT_NEAR(l.vertexMaxMm, e.max, 1e-3 + 1e-4 * e.max);
      EXPECT_LE(l.vertexMeanMm, l.vertexP95Mm + 1e-9);
      EXPECT_LE(l.vertexP95Mm, l.vertexMaxMm + 1e-9);
    }
    // Expected normal error: 0 with maps, acos(z) of the truth's texels without.
    if (l.normalMaps) {
      EXPECT_LT(l.normalMeanDeg, 0.01);
    } else {
      double sum = 0;
      size_t texels = 0;
      for (const auto& p : poses)
        for (size_t t = 0; t + 1 < p.normalMap.xy.size(); t += 2) {
          const double x = p.normalMap.xy[t], y = p.normalMap.xy[t + 1];
          const double z = std::sqrt(std::max(0.0, 1.0 - x * x - y * y));
          sum += std::acos(z / std::sqrt(x * x + y * y + z * z)) * 180.0 / M_PI, ++texels;
        }
      EXPECT_GT(sum / double(texels), 5.0);  // the random codebook tilts the normals well away from flat
      EXPECT_NEAR(l.normalMeanDeg, sum / double(texels), 1e-6);
    }
  }
}

// On a truth the bake's evaluation measures too (the rest shape pushed about, random maps), the full
// level IS the evaluation's total (vertex and normal map) and the skinned level its mean-shape baseline:
// same poses, same path.
TEST(QualityLadder, FullLevelIsTheEvaluationsTotalAndSkinnedItsMeanShapeBaseline) {
  SWISH_TEST_SEED_SCOPE(seed, 2102);
  Rng rng(seed);
  const Model m = test::makeRandomModel(rng, smallSpec());
  const size_t n = m.gameMesh.vertexCount();
  std::vector<DatasetPose> poses(9);
  for (uint32_t i = 0; i < poses.size(); ++i) {
    DatasetPose& p = poses[i];
    p.id = 100 + i;
    p.pose = test::makeRandomPose(rng, m.skeleton, 0.6f);
    p.gameMeshPreSkin = m.gameMesh.positions;
    for (Eigen::Index k = 0; k < p.gameMeshPreSkin.size(); ++k)
      p.gameMeshPreSkin.data()[k] += float(rng.normal(0, 0.01));
    p.gameMeshWorld = skinPositions(p.gameMeshPreSkin, m.gameMesh.skin, m.skeleton.skinningMatrices(p.pose));
    p.normalMap = {m.normalMaps.width, m.normalMaps.height,
                   std::vector<float>(size_t(m.normalMaps.width) * m.normalMaps.height * 2)};
    for (float& x : p.normalMap.xy) x = float(rng.uniformf(-0.5f, 0.5f));
  }
  std::vector<const DatasetPose*> ptrs;
  std::vector<const NormalMapImage*> uncompressed;
  std::vector<NormalMapImage> decoded;
  for (const auto& p : poses) ptrs.push_back(&p);
  for (uint32_t k = 0; k < m.normalMaps.mapCount(); ++k) decoded.push_back(decodeVqMap(m.normalMaps, k));
  for (const auto& d : decoded) uncompressed.push_back(&d);
  std::vector<const NormalMapImage*> mapsForPca;
  for (const auto& p : poses) mapsForPca.push_back(&p.normalMap);
  const NormalMapPca normalPca = fitNormalMapPca(mapsForPca, m.normalCodeDims(), seed);
  const BakeEvaluation ev = evaluateModel(m, ptrs, uncompressed, &normalPca.pca);
  ASSERT_EQ(n, size_t(m.gameMesh.positions.rows()));

  const QualityLadder l = measureLadder(m, ptrs, "the evaluation's poses");
  ASSERT_GE(l.size(), 3u);
  const QualityLevel& full = l.levels.front();
  ASSERT_EQ(full.meshComponents, uint32_t(m.meshComponents()));
  ASSERT_TRUE(full.normalMaps);
  EXPECT_DOUBLE_EQ(full.vertexMeanMm, ev.totalMm.mean);
  EXPECT_DOUBLE_EQ(full.vertexP95Mm, ev.totalMm.p95);
  EXPECT_DOUBLE_EQ(full.vertexMaxMm, ev.totalMm.max);
  EXPECT_DOUBLE_EQ(full.normalMeanDeg, ev.normalTotal.meanDegrees);
  const QualityLevel& skinned = l.levels.back();
  ASSERT_EQ(skinned.meshComponents, 0u);
  EXPECT_DOUBLE_EQ(skinned.vertexMeanMm, ev.meanSkinnedMm.mean);
  EXPECT_DOUBLE_EQ(skinned.vertexP95Mm, ev.meanSkinnedMm.p95);
  EXPECT_DOUBLE_EQ(skinned.vertexMaxMm, ev.meanSkinnedMm.max);
  // The k/2 level with maps shades with the same selected map as the full one.
  ASSERT_TRUE(l.levels[1].normalMaps);
  EXPECT_DOUBLE_EQ(l.levels[1].normalMeanDeg, full.normalMeanDeg);

  // A model without a normal-map database: the levels shade with the flat map, still measured against
  // the poses' truth maps; the ladder has no map level.
  Model flatModel = m;
  flatModel.normalMaps = NormalMapDatabase{};
  const QualityLadder flat = measureLadder(flatModel, ptrs, "the same poses");
  for (const QualityLevel& x : flat.levels) {
    EXPECT_FALSE(x.normalMaps);
    EXPECT_TRUE(std::isfinite(x.normalMeanDeg));
    EXPECT_DOUBLE_EQ(x.normalMeanDeg, flat.levels.back().normalMeanDeg);
  }
  // Poses without truth maps: the normal error is not measured (NaN), the vertex error still is.
  std::vector<DatasetPose> bare(poses.begin(), poses.begin() + 3);
  for (auto& p : bare) p.normalMap = {};
  std::vector<const DatasetPose*> barePtrs;
  for (const auto& p : bare) barePtrs.push_back(&p);
  const QualityLadder noMaps = measureLadder(m, barePtrs, "bare");
  EXPECT_TRUE(std::isnan(noMaps.levels[0].normalMeanDeg));
  EXPECT_TRUE(std::isfinite(noMaps.levels[0].vertexMeanMm));
}

// A truth that IS the mean shape skinned: the cheapest level is exact and every dearer one is worse,
// which the check reports (naming both levels) without reordering anything.
TEST(QualityLadder, ALevelWorseThanACheaperOneIsReported) {
  SWISH_TEST_SEED_SCOPE(seed, 2103);
  Rng rng(seed);
  const Model m = test::makeRandomModel(rng, smallSpec());
  const size_t n = m.gameMesh.vertexCount();
  Points3f mean(Eigen::Index(n), 3);
  for (size_t v = 0; v < n; ++v)
    for (int a = 0; a < 3; ++a) mean(Eigen::Index(v), a) = m.meshPca.mean[Eigen::Index(3 * v + size_t(a))];
  std::vector<DatasetPose> poses(4);
  std::vector<const DatasetPose*> ptrs;
  for (uint32_t i = 0; i < poses.size(); ++i) {
    poses[i].id = i;
    poses[i].pose = test::makeRandomPose(rng, m.skeleton, 0.6f);
    poses[i].gameMeshWorld = skinPositions(mean, m.gameMesh.skin, m.skeleton.skinningMatrices(poses[i].pose));
    ptrs.push_back(&poses[i]);
  }
  const QualityLadder l = measureLadder(m, ptrs, "mean shapes");
  const std::vector<std::string> names = [&] {
    std::vector<std::string> v;
    for (const auto& x : l.levels) v.push_back(x.name);
    return v;
  }();
  EXPECT_EQ(names, (std::vector<std::string>{"full", "k4", "k2-flat", "k1-flat", "skinned"}));  // as given
  EXPECT_LT(l.levels.back().vertexMaxMm, 1e-3);
  EXPECT_GT(l.levels.front().vertexMeanMm, 0.1);
  const std::vector<std::string> problems = ladderProblems(l);
  ASSERT_FALSE(problems.empty());
  bool fullVsSkinned = false;
  for (const std::string& p : problems)
    fullVsSkinned |= p.find("level 'full'") != std::string::npos &&
                     p.find("cheaper level 'skinned'") != std::string::npos && p.find("vertex") != std::string::npos;
  EXPECT_TRUE(fullVsSkinned) << problems.front();
  const std::string md = ladderMarkdown(l, nullptr, "plot.svg");
  EXPECT_NE(md.find("Not monotone"), std::string::npos);
  EXPECT_NE(md.find("| skinned | 0 | no |"), std::string::npos) << md;
  EXPECT_NE(md.find("![error against CPU time per level](plot.svg)"), std::string::npos);
  EXPECT_EQ(ladderReportJson(l)["problems"].size(), problems.size());
}

// The check on hand-written figures: a monotone ladder has no problem; one dearer level worse than a
// cheaper one gives exactly that pair, for the vertex error and the normal error separately; NaN
// (not measured) is never a problem.
TEST(QualityLadder, MonotonicityOnHandWrittenFigures) {
  QualityLadder l;
  const auto level = [](const char* name, uint32_t k, bool maps, double mm, double deg) {
    QualityLevel x;
    x.name = name, x.meshComponents = k, x.normalMaps = maps, x.vertexMeanMm = mm, x.normalMeanDeg = deg;
    return x;
  };
  l.levels = {level("full", 16, true, 1.0, 4.0), level("k8", 8, true, 1.5, 4.0), level("k4-flat", 4, false, 2.0, 9.0),
              level("skinned", 0, false, 6.0, 9.0)};
  EXPECT_TRUE(ladderProblems(l).empty());
  l.levels[1].vertexMeanMm = 2.5;  // k8 now worse than k4-flat
  std::vector<std::string> p = ladderProblems(l);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("level 'k8' (k 8, maps) has a larger vertex mean error (2.50 mm) than the cheaper level "
                      "'k4-flat' (k 4, no maps: 2.00 mm)"),
            std::string::npos)
      << p[0];
  l.levels[1].vertexMeanMm = 1.5;
  l.levels[0].normalMeanDeg = 9.5;  // full's maps worse than the flat map
  p = ladderProblems(l);
  ASSERT_EQ(p.size(), 3u);  // worse than k8, k4-flat and skinned
  EXPECT_NE(p[0].find("normal-map mean error (9.50 deg)"), std::string::npos) << p[0];
  l.levels[0].normalMeanDeg = std::nan("");
  EXPECT_TRUE(ladderProblems(l).empty());
}

// CPU time per level: nothing for the mean shape skinned; the network (and the lookup with maps) for
// the others, the same for levels of the same kind (the work does not depend on k); the machine named.
TEST(QualityLadder, CpuTimePerLevel) {
  SWISH_TEST_SEED_SCOPE(seed, 2104);
  Rng rng(seed);
  const Model m = test::makeRandomModel(rng, smallSpec());
  std::vector<Pose> poses;
  for (int i = 0; i < 5; ++i) poses.push_back(test::makeRandomPose(rng, m.skeleton, 0.6f));
  std::vector<const Pose*> ptrs;
  for (const auto& p : poses) ptrs.push_back(&p);
  QualityLadder l = runtime::defaultLadder(m);
  LadderTimingOptions o;
  o.characters = 6, o.repeats = 15, o.warmup = 2;
  timeLadderCpu(m, ptrs, l, o);
  EXPECT_EQ(l.levels.back().cpuUsPerCharacter, 0.0);
  for (const QualityLevel& x : l.levels) {
    if (!x.needsNetwork()) continue;
    EXPECT_GT(x.cpuUsPerCharacter, 0.0) << x.name;
    EXPECT_TRUE(std::isfinite(x.cpuUsPerCharacter)) << x.name;
  }
  EXPECT_EQ(l.levels[0].cpuUsPerCharacter, l.levels[1].cpuUsPerCharacter);  // both with maps
  EXPECT_EQ(l.levels[2].cpuUsPerCharacter, l.levels[3].cpuUsPerCharacter);  // both flat
  EXPECT_NE(l.timedOn.find("1 thread"), std::string::npos) << l.timedOn;
  EXPECT_NE(l.timedOn.find("batches of 6"), std::string::npos) << l.timedOn;
  const QualityLadder stored = withoutTimes(l);
  for (const QualityLevel& x : stored.levels) EXPECT_TRUE(std::isnan(x.cpuUsPerCharacter));
  EXPECT_TRUE(stored.timedOn.empty());
  EXPECT_THROW(timeLadderCpu(m, {}, l, o), Error);
}

TEST(QualityLadder, BadInputIsAnErrorNamingThePose) {
  SWISH_TEST_SEED_SCOPE(seed, 2105);
  Rng rng(seed);
  const Model m = test::makeRandomModel(rng, smallSpec());
  EXPECT_NE(test::errorOf([&] { measureLadder(m, {}, "none"); }).find("no pose"), std::string::npos);
  DatasetPose p;
  p.id = 7;
  p.pose = test::makeRandomPose(rng, m.skeleton, 0.3f);
  p.gameMeshWorld = Points3f::Zero(3, 3);
  EXPECT_NE(test::errorOf([&] { measureLadder(m, {&p}, "x"); }).find("pose 7 has a game mesh of 3 vertices"),
            std::string::npos);
  p.gameMeshWorld = m.gameMesh.positions;
  p.normalMap = {4, 4, std::vector<float>(32, 0.f)};  // the database's maps are 8x8
  EXPECT_NE(test::errorOf([&] { measureLadder(m, {&p}, "x"); }).find("pose 7: its normal map is 4x4"),
            std::string::npos);
  QualityLadder tooDeep = runtime::defaultLadder(m);
  tooDeep.levels[0].meshComponents = 99;
  p.normalMap = {};
  EXPECT_NE(test::errorOf([&] { measureLadder(m, {&p}, tooDeep, "x"); }).find("reads 99 components"),
            std::string::npos);
}
