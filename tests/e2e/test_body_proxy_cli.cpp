// `swish body-proxy MODEL`: the push-out's body anchors re-fitted on a model already baked. Runs the swish
// program on the committed default model: without clips (no slide anchors: they need simulated poses),
// with 2 simulated frames of a training clip and --uncalibrated (slide and cover anchors, every clearance
// at the margin), and with a clip that is not there (a clear error, nothing written).
#include <gtest/gtest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "support/paths.hpp"
#include "support/swish_cli.hpp"
#include "support/temp_dir.hpp"
#include "swish/model/model_file.hpp"

using namespace swish;
namespace fs = std::filesystem;

namespace {

using test::readText;
using test::swishCmd;
fs::path defaultModel() { return test::committedDefaultModel(); }

}  // namespace

TEST(BodyProxyCli, SlideAnchorsFromSimulatedClipFramesAndTheMarginAsked) {
  if (!fs::exists(defaultModel())) GTEST_SKIP() << "no committed default model at " << defaultModel();
  if (!fs::exists(test::debianMocap("01_01.bvh")))
    GTEST_SKIP() << "no CMU clips (Debian package assimp-testmodels): the default model's own clips";
  const test::TempDir tmp("body_proxy_cli");
  const std::string before = readText(defaultModel());

  const fs::path plain = tmp / "plain.swish";
  const cluster::CommandResult a =
      swishCmd({"body-proxy", defaultModel().string(), "--margin-mm", "4", "--out", plain.string()});
  ASSERT_EQ(a.exitCode, 0) << a.out << a.err;
  EXPECT_NE(a.out.find("0 of them where the cloth slides to on its own part (0 poses: they need --clips)"),
            std::string::npos)
      << a.out;
  const Model p = loadModel(plain);
  EXPECT_FLOAT_EQ(p.bodyAnchors.margin, 0.004f);
  EXPECT_EQ(nlohmann::json::parse(p.metadata)["body_anchors"]["slide_anchored"], 0);

  const fs::path slid = tmp / "slid.swish";
  const cluster::CommandResult b =
      swishCmd({"body-proxy", defaultModel().string(), "--margin-mm", "4", "--clips",
                test::debianMocap("01_01.bvh").string(), "--poses", "2", "--uncalibrated", "--out", slid.string()});
  ASSERT_EQ(b.exitCode, 0) << b.out << b.err;
  EXPECT_NE(b.out.find("Not calibrated (--uncalibrated): every anchor keeps the 4.0 mm margin."), std::string::npos)
      << b.out;
  const Model s = loadModel(slid);
  const auto anchors = nlohmann::json::parse(s.metadata)["body_anchors"];
  EXPECT_EQ(anchors["slide_poses"], 2);
  EXPECT_GT(anchors["slide_anchored"].get<size_t>(), 0u) << anchors.dump();
  EXPECT_FALSE(anchors.contains("calibration")) << anchors.dump();
  ASSERT_EQ(s.bodyAnchors.second.size(), s.gameMesh.vertexCount());
  // The slide anchors fill second slots the plain fit left empty; the other-part ones stay as they were.
  size_t filled = 0;
  for (size_t v = 0; v < s.gameMesh.vertexCount(); ++v) {
    const bool had = !p.bodyAnchors.second.empty() && p.bodyAnchors.second[v].present();
    if (had) {
      EXPECT_EQ(s.bodyAnchors.second[v].position, p.bodyAnchors.second[v].position) << v;
    }
    if (!had && s.bodyAnchors.second[v].present()) ++filled;
    if (s.bodyAnchors.anchors[v].present()) {
      EXPECT_FLOAT_EQ(s.bodyAnchors.anchors[v].clearance, 0.004f) << v;
    }
  }
  EXPECT_EQ(filled, anchors["slide_anchored"].get<size_t>());
  // The third set (cover anchors, format 1.5): where the first two still miss the skin under the cloth.
  EXPECT_GT(anchors["cover_anchored"].get<size_t>(), 0u) << anchors.dump();
  EXPECT_EQ(s.bodyAnchors.anchored(2), anchors["cover_anchored"].get<size_t>());
  EXPECT_LE(anchors["cover_covered"].get<size_t>(), anchors["cover_misses"].get<size_t>());
  EXPECT_NE(b.out.find("with a third (cover) anchor"), std::string::npos) << b.out;
  for (const BodyAnchor& a : s.bodyAnchors.third)
    if (a.present()) {
      EXPECT_FLOAT_EQ(a.clearance, 0.004f);
    }
  EXPECT_TRUE(p.bodyAnchors.third.empty()) << "no poses, no cover anchors";

  const fs::path never = tmp / "never.swish";
  const cluster::CommandResult c = swishCmd(
      {"body-proxy", defaultModel().string(), "--clips", (tmp / "gone.bvh").string(), "--out", never.string()});
  EXPECT_NE(c.exitCode, 0);
  EXPECT_NE((c.out + c.err).find("gone.bvh"), std::string::npos) << c.out << c.err;
  EXPECT_FALSE(fs::exists(never));
  EXPECT_EQ(readText(defaultModel()), before) << "the committed model is never written";
}
