// `swish levels MODEL`: the quality ladder of a model already baked, measured against the bake's source
// simulation of frames of the clips the model was baked from, written into a copy of the model. Runs the
// swish program on the committed default model with 2 truth poses (about 4 s of CPU each at the bake's
// own settings: a coarser truth measures the coarseness, tens of mm, instead of the model), and its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "support/paths.hpp"
#include "support/swish_cli.hpp"
#include "support/temp_dir.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/quality_levels.hpp"

using namespace swish;
namespace fs = std::filesystem;

namespace {

using test::readText;
using test::swishCmd;
fs::path defaultModel() { return test::committedDefaultModel(); }

}  // namespace

TEST(LevelsCli, MeasuresTheDefaultModelsLadderAgainstItsSourceSimulation) {
  if (!fs::exists(defaultModel())) GTEST_SKIP() << "no committed default model at " << defaultModel();
  if (!fs::exists(test::debianMocap("01_01.bvh")) || !fs::exists(test::debianMocap("01_03.bvh")))
    GTEST_SKIP() << "no CMU clips (Debian package assimp-testmodels): the default model's own clips";
  const test::TempDir tmp("levels_cli");
  const fs::path out = tmp / "models" / "default_levels.swish", report = tmp / "report";
  const std::string before = readText(defaultModel());
  // The clips are given: the default model is baked from the motion corpus of ../shared/mocap, and its
  // metadata names those clips where the bake read them. Debian's 01_01 and 01_03 are two of the corpus's
  // training clips (subject 01, at their recorded 120 fps).
  const cluster::CommandResult r =
      swishCmd({"levels", defaultModel().string(), "--clips", test::debianMocap("01_01.bvh").string(),
                test::debianMocap("01_03.bvh").string(), "--frames", "2", "--threads", "2", "--out", out.string(),
                "--report", report.string(),
                // The truth overrides are `swish replay`'s (truth_options.hpp); the bake's own clearance, said.
                "--truth-limb-clearance-mm", "15"});
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("truth 2/2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("s left"), std::string::npos) << r.out;
  EXPECT_EQ(readText(defaultModel()), before);  // --out: the model given is left as it was

  const Model m = loadModel(out);
  const Model original = loadModel(defaultModel());
  const auto meta = nlohmann::json::parse(m.metadata), meta0 = nlohmann::json::parse(original.metadata);
  ASSERT_TRUE(meta.contains(runtime::kQualityLevelsKey));
  for (const auto& [key, value] : meta0.items()) {  // the rest is kept (the ladder is measured anew)
    if (key != runtime::kQualityLevelsKey) {
      EXPECT_EQ(meta[key], value) << key;
    }
  }
  const runtime::QualityLadder l = runtime::ladderOf(m);
  ASSERT_EQ(l.size(), 5u);  // K = 128 with maps: full, k64, k32-flat, k16-flat, skinned
  EXPECT_GE(l.poses, 1u);
  EXPECT_LE(l.poses, 2u);
  EXPECT_NE(l.measuredOn.find("the clips 01_01.bvh, 01_03.bvh"), std::string::npos) << l.measuredOn;
  EXPECT_NE(l.measuredOn.find("overridden for this run (not the bake's): limb clearance 15 mm"), std::string::npos)
      << l.measuredOn;
  EXPECT_FALSE(l.timedOn.empty());
  const runtime::QualityLevel &full = l.levels.front(), &skinned = l.levels.back();
  // The default model's held-out error is 14.8 mm mean, 33 mm p95 on random held-out frames of its
  // training clips (assets/default/report); the mean shape alone misses the pose's correctives.
  EXPECT_GT(full.vertexMeanMm, 0.1);
  EXPECT_LT(full.vertexMeanMm, 33.0);
  EXPECT_GT(skinned.vertexMeanMm, 2.0 * full.vertexMeanMm);
  EXPECT_TRUE(std::isfinite(full.normalMeanDeg));
  EXPECT_GT(full.cpuUsPerCharacter, 0.0);
  EXPECT_EQ(skinned.cpuUsPerCharacter, 0.0);
  EXPECT_TRUE(std::isnan(full.gpuUsPerCharacter));

  EXPECT_TRUE(fs::exists(report / "levels.md"));
  EXPECT_TRUE(fs::exists(report / "quality_levels.svg"));
  const auto j = nlohmann::json::parse(readText(report / "levels.json"));
  EXPECT_EQ(j["frames"].size(), 2u);
  EXPECT_FALSE(j["clips_are_the_models_own"].get<bool>());  // --clips given
  EXPECT_EQ(j["quality_levels"]["levels"].size(), 5u);
}

TEST(LevelsCli, ErrorsNameTheFile) {
  const test::TempDir tmp("levels_cli_errors");
  const cluster::CommandResult missing = swishCmd({"levels", (tmp / "nope.swish").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nope.swish"), std::string::npos) << missing.err;
  if (!fs::exists(defaultModel())) GTEST_SKIP() << "no committed default model at " << defaultModel();
  const fs::path out = tmp / "out.swish";
  const cluster::CommandResult clip =
      swishCmd({"levels", defaultModel().string(), "--clips", (tmp / "gone.bvh").string(), "--out", out.string()});
  EXPECT_EQ(clip.exitCode, 1);
  EXPECT_NE(clip.err.find("gone.bvh does not exist"), std::string::npos) << clip.err;
  EXPECT_FALSE(fs::exists(out));  // nothing written
  const cluster::CommandResult range =
      swishCmd({"levels", defaultModel().string(), "--truth-cover-mm", "50", "--out", out.string()});
  EXPECT_NE(range.exitCode, 0);
  EXPECT_NE((range.out + range.err).find("--truth-cover-mm"), std::string::npos) << range.out << range.err;
  EXPECT_FALSE(fs::exists(out));
  // A model with no bake behind it (no metadata naming the character): no truth, and it says why.
  const fs::path bare = tmp / "bare.swish";
  Model m = loadModel(defaultModel());
  m.metadata = "{}";
  saveModel(m, bare);
  const cluster::CommandResult noTruth = swishCmd({"levels", bare.string(), "--out", out.string()});
  EXPECT_EQ(noTruth.exitCode, 1);
  EXPECT_NE(noTruth.err.find("bare.swish: no truth to measure the levels against"), std::string::npos) << noTruth.err;
  EXPECT_FALSE(fs::exists(out));
}
