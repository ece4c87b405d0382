// swish replay --truth-every N: the bake's source simulation run on every Nth frame (replay/
// truth_simulation.hpp), with the committed default model on a tiny scene and a cheaper simulation
// (the substeps are overridden, halved):
// figures present, finite and plausible, only on the N grid, the same twice and far from the origin;
// a model whose character cannot be rebuilt gets a note and no truth; the settings the truth reads
// from a model's metadata are the ones the bake used.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "support/error_message.hpp"
#include "support/gpu_test.hpp"
#include "support/paths.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/pose_stream.hpp"
#include "swish/replay/replay_engine.hpp"
#include "swish/replay/replay_job.hpp"
#include "swish/replay/replay_render.hpp"
#include "swish/replay/report_writer.hpp"
#include "swish/replay/truth_simulation.hpp"
#include "swish/runtime/scene_file.hpp"

namespace {

using namespace swish;
namespace fs = std::filesystem;
using nlohmann::json;

fs::path defaultModelFile() { return test::sourceDir() / "assets/default/default.swish"; }

// Cheaper than the bake's simulation for a unit test: its 6568 vertices, half its 12 substeps (1.5 s
// of CPU for the A-pose against 1.9 s; the transfer and normal-map bake cost the same). Coarser does
// not do: the welded game mesh at 4 substeps cannot hold the jersey's narrow top band (attach_band
// 0.03) and tears even in the A-pose, and at 6-8 substeps it slides 8-12 cm further down than the
// bake's cloth, which would measure the coarseness instead of the model.
replay::TruthOptions cheaperTruth(uint32_t every) {
  replay::TruthOptions t;
  t.every = every;
  t.substeps = 6;
  return t;
}

// `swish replay --render` at thumbnail size with the validation layers on.
replay::ReplayRenderOptions smallPictures(uint32_t frames) {
  replay::ReplayRenderOptions ro;
  ro.maxFrames = frames;
  ro.width = 96;
  ro.height = 128;
  ro.validation = true;
  return ro;
}

class ReplayTruth : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    if (!fs::exists(defaultModelFile())) GTEST_SKIP() << "no committed default model at " << defaultModelFile();
    if (!fs::exists(test::debianMocap("01_01.bvh"))) GTEST_SKIP() << "no CMU clip (Debian package assimp-testmodels)";
    tmp_.emplace("replay_truth");
    model_ = loadModel(defaultModelFile());
    // A character standing in the A-pose: its truth simulation cannot fail, whatever the clip does.
    replay::PoseStream rest;
    for (const auto& j : model_.skeleton.joints) rest.joints.push_back(j.name);
    const Pose p = model_.skeleton.restPose();
    for (int f = 0; f < 8; ++f)
      rest.frames.push_back({p.rootTranslation, p.local, std::vector<bool>(p.local.size(), true)});
    replay::writePoseStream(*tmp_ / "rest.json", rest);
  }
  void TearDown() override {
    tmp_.reset();
    test::GpuTest::TearDown();
  }

  json character(const std::string& name, bool clip, std::array<double, 3> at = {0, 0, 0}) const {
    json c{{"name", name},
           {"model", defaultModelFile().string()},
           {"placement", {{"translation", at}, {"yawDegrees", 0.0}}}};
    if (clip)
      c["animation"] = {{"file", test::debianMocap("01_01.bvh").string()}, {"timeOffset", 2.0}, {"speed", 1.0}};
    else
      c["poseStream"] = "rest.json";
    return c;
  }
  runtime::Scene scene(uint32_t frames, const json& characters) const {
    json j{{"name", "truth"},
           {"frames", {{"count", frames}, {"rate", 30}}},
           {"outputs", {{"directory", "out"}, {"render", true}, {"gpuCheckEvery", 100}}},
           {"characters", characters}};
    return runtime::parseScene(j, *tmp_ / "scene.json");
  }
  replay::ReplayResult run(const runtime::Scene& s, const replay::TruthOptions& truth) {
    replay::ModelLibrary lib(s);
    replay::ReplayOptions o;
    o.context = &ctx();
    o.truth = truth;
    o.pushOut = true;        // runs where the model has body anchors (the committed one has none)
    o.penetrationEvery = 1;  // every frame, every character
    replay::ReplayEngine engine(s, lib, o);
    return engine.run();
  }

  std::optional<test::TempDir> tmp_;
  Model model_;
};

TEST_F(ReplayTruth, EveryNthFrameIsMeasuredAgainstTheSourceSimulation) {
  const runtime::Scene s = scene(5, json::array({character("walker", true), character("rest", false)}));
  replay::ReplayJobOptions jo;
  jo.quiet = true;
  jo.engine.context = &ctx();
  jo.engine.truth = cheaperTruth(2);
  jo.engine.pushOut = true;        // runs where the model has body anchors (the committed one has none)
  jo.engine.penetrationEvery = 1;  // every frame, every character
  uint32_t progressCalls = 0, lastDone = 0, lastTotal = 0;
  jo.engine.truthProgress = [&](uint32_t done, uint32_t total) { ++progressCalls, lastDone = done, lastTotal = total; };
  const replay::ReplayJobResult job = replay::runReplayJob(s, jo);
  const replay::ReplayResult& r = job.result;
  EXPECT_TRUE(r.truthAvailable);
  EXPECT_NE(r.truthNote.find("ground truth every 2 frames"), std::string::npos) << r.truthNote;
  EXPECT_NE(r.truthNote.find("overridden"), std::string::npos) << r.truthNote;
  EXPECT_EQ(progressCalls, 6u);
  EXPECT_EQ(lastDone, 6u);
  EXPECT_EQ(lastTotal, 6u);

  ASSERT_EQ(r.frames.size(), 5u);
  EXPECT_EQ(r.truthFrames, 3u);
  uint32_t measured = 0;
  for (const auto& f : r.frames) {
    const bool onGrid = (f.frame - s.firstFrame) % 2 == 0;
    EXPECT_EQ(f.truthFrame, onGrid) << "frame " << f.frame;
    if (!onGrid) {
      EXPECT_TRUE(f.truth.empty()) << "frame " << f.frame;
      continue;
    }
    ASSERT_EQ(f.truth.size(), 2u) << "frame " << f.frame;
    for (const auto& c : f.truth) {
      if (!c.ok) {  // a clip pose the cheaper solve fails on: the bake leaves such poses out too
        EXPECT_EQ(c.character, 0u) << c.failure;
        EXPECT_FALSE(c.failure.empty());
        continue;
      }
      ++measured;
      // The bake measured this model at 5.5 mm mean, 69 mm max on its held-out poses, and 7.7 mm on
      // the rest pose it trained on; half the substeps add a few mm (rest pose: 10.5 mm in all) to a
      // few cm where folds fall the other way.
      EXPECT_TRUE(std::isfinite(c.meanMm) && std::isfinite(c.p95Mm) && std::isfinite(c.maxMm));
      EXPECT_GT(c.meanMm, 0.0);
      EXPECT_LT(c.meanMm, 40.0) << "character " << c.character << " frame " << f.frame;
      EXPECT_LE(c.meanMm, c.maxMm);
      EXPECT_LE(c.p95Mm, c.maxMm);
      EXPECT_LT(c.maxMm, 200.0);
      ASSERT_TRUE(c.normalMap);
      EXPECT_TRUE(std::isfinite(c.meanDeg));
      EXPECT_LT(c.meanDeg, 30.0);
      EXPECT_GT(c.seconds, 0.0);
      EXPECT_GT(c.cpuSeconds, 0.0);
    }
    EXPECT_TRUE(f.truth[1].ok) << "the A-pose must simulate: " << f.truth[1].failure;
  }
  EXPECT_EQ(r.truthOverall.samples, measured);
  EXPECT_EQ(r.truthOverall.samples + r.truthOverall.failed, 6u);
  EXPECT_LT(r.truthOverall.meanMm, 40.0);
  ASSERT_EQ(r.truthPerCharacter.size(), 2u);
  EXPECT_EQ(r.truthPerCharacter[1].samples, 3u);

  // The report carries the figures beside the times, per character and overall, and plots them.
  std::ifstream in(job.directory / "report.json");
  const json rep = json::parse(in);
  EXPECT_EQ(rep["truth"]["every"], 2);
  EXPECT_NEAR(rep["truth"]["overall"]["meanMm"].get<double>(), r.truthOverall.meanMm, 1e-9);
  EXPECT_TRUE(rep["truth"]["overall"]["normalMeanDeg"].is_number());
  EXPECT_EQ(rep["characters"][1]["truth"]["samples"], 3);
  EXPECT_TRUE(rep["frames"][0]["truth"][1]["meanMm"].is_number());
  EXPECT_FALSE(rep["frames"][1].contains("truth"));
  EXPECT_TRUE(rep["frames"][0]["times"]["mlp"].is_number());
  std::ifstream md(job.directory / "report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Run time against ground truth"), std::string::npos) << text;
  EXPECT_NE(text.find("Ground truth per character"), std::string::npos);
  EXPECT_TRUE(fs::exists(job.directory / "plots/truth_error_per_frame.svg"));

  // Penetration into the bake's body, every frame, every character: the model's reconstruction and,
  // when the model carries body anchors, the same after the push-out, which the GPU ran and the truth
  // measured (beside the error without it). The committed model has none (see README): its figures
  // are measured on a copy given one by `swish body-proxy`.
  EXPECT_NE(r.penetrationNote.find("the body of the bake's character"), std::string::npos) << r.penetrationNote;
  const bool proxy = !model_.bodyAnchors.empty();
  EXPECT_EQ(r.pushOut, proxy);
  for (const auto& f : r.frames) {
    ASSERT_EQ(f.penetration.size(), 2u) << "frame " << f.frame;
    for (const auto& p : f.penetration) {
      EXPECT_EQ(p.model.vertices, model_.gameMesh.vertexCount());
      EXPECT_LE(p.model.visible, p.model.inside);
      EXPECT_EQ(p.pushedMeasured, proxy);
      EXPECT_TRUE(std::isfinite(p.model.deepestMm) && p.model.deepestMm < 150.0);
    }
    for (const auto& c : f.truth)
      if (c.ok) {
        EXPECT_EQ(c.comparedWithout, proxy) << "frame " << f.frame;
      }
  }
  // Every level of the model's ladder against the same truth: the full level is the run time's own
  // output (the CPU reference of the GPU's frame, within the GPU check's tolerance), and the mean shape
  // skinned is far worse.
  ASSERT_EQ(r.levels.size(), 1u);
  ASSERT_EQ(r.levels[0].truth.size(), r.levels[0].ladder.size());
  EXPECT_NEAR(r.levels[0].truth[0].meanMm, r.truthOverall.meanMm, replay::kPositionToleranceMm);
  EXPECT_GT(r.levels[0].truth.back().meanMm, 2.0 * r.levels[0].truth[0].meanMm);
  EXPECT_EQ(r.levels[0].truth[0].samples, r.levels[0].truth.back().samples);
  EXPECT_TRUE(rep["levels"]["models"][0]["truth"][0]["meanMm"].is_number());
  EXPECT_EQ(r.penetrationOverall.model.frames, 10u);
  EXPECT_TRUE(rep["penetration"]["overall"]["model"]["deepestMm"].is_number());
  EXPECT_TRUE(rep["frames"][0]["penetration"][0]["model"]["inside"].is_number());
  if (proxy) {
    EXPECT_LE(r.penetrationOverall.pushed.deepestMm, r.penetrationOverall.model.deepestMm + 1e-9);
    EXPECT_TRUE(r.truthOverall.comparedWithout);
    EXPECT_TRUE(rep["truth"]["overall"]["withoutPushOut"]["meanMm"].is_number());
    // Split by where the truth lies: the two sides partition the vertices, so their means mix back to the whole.
    const replay::TruthSummary& t = r.truthOverall;
    ASSERT_TRUE(t.splitByTruth);
    EXPECT_GE(t.truthInsideShare, 0.0);
    EXPECT_LE(t.truthInsideShare, 1.0);
    const double q = t.truthInsideShare;
    EXPECT_NEAR((1 - q) * t.meanMmTruthOutside + q * t.meanMmTruthInside, t.meanMm, 1e-6 * t.meanMm);
    EXPECT_NEAR((1 - q) * t.meanMmWithoutTruthOutside + q * t.meanMmWithoutTruthInside, t.meanMmWithout,
                1e-6 * t.meanMmWithout);
    EXPECT_TRUE(rep["truth"]["overall"]["withoutPushOut"]["byTruth"]["truthOutside"]["meanMm"].is_number());
    EXPECT_NE(text.find("Split by where the truth lies"), std::string::npos);
  }
  EXPECT_NE(text.find("Garment inside the body"), std::string::npos);
  EXPECT_TRUE(fs::exists(job.directory / "plots/penetration_per_frame.svg"));
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

// The pool splits the push-out's change by where the truth lies, vertex by vertex, only when every
// measured pose says where (a pose without a body says nothing, and then no split is claimed).
TEST(ReplayTruthPool, SplitsThePushOutsChangeByWhereTheTruthLies) {
  replay::TruthMeasurement a;
  a.summary.ok = true;
  a.vertexMm = {1, 2, 10, 20};
  a.vertexMmWithout = {1, 2, 4, 8};
  a.truthInside = {0, 0, 1, 1};
  replay::TruthMeasurement b = {};
  b.summary.ok = true;
  b.vertexMm = {3, 5};
  b.vertexMmWithout = {4, 5};
  b.truthInside = {0, 1};
  replay::TruthPool pool;
  pool.add(a);
  pool.add(b);
  const replay::TruthSummary s = pool.summary();
  ASSERT_TRUE(s.splitByTruth);
  EXPECT_DOUBLE_EQ(s.truthInsideShare, 0.5);
  EXPECT_DOUBLE_EQ(s.meanMmTruthOutside, 2.0);             // 1, 2, 3
  EXPECT_DOUBLE_EQ(s.meanMmWithoutTruthOutside, 7.0 / 3);  // 1, 2, 4
  EXPECT_DOUBLE_EQ(s.meanMmTruthInside, 35.0 / 3);         // 10, 20, 5
  EXPECT_DOUBLE_EQ(s.meanMmWithoutTruthInside, 17.0 / 3);  // 4, 8, 5
  replay::TruthMeasurement c;
  c.summary.ok = true;
  c.vertexMm = {1};
  c.vertexMmWithout = {1};  // no body: no truthInside
  pool.add(c);
  EXPECT_TRUE(pool.summary().comparedWithout);
  EXPECT_FALSE(pool.summary().splitByTruth);
}

// `swish replay --render` on the default model draws the mannequin, and measures on each picture the skin
// the jersey covers at rest that is drawn where the jersey should be (body_through_garment.hpp); the
// report's section gives the frames that show it and the pixels of each.
TEST_F(ReplayTruth, RenderMeasuresTheBodyThroughTheGarmentPerFrame) {
  const runtime::Scene s = scene(6, json::array({character("walker", true)}));
  replay::ModelLibrary models(s);
  const replay::ReplayRenderOptions ro = smallPictures(2);
  const fs::path dir = *tmp_ / "out/render";
  const replay::ReplayRenderResult r = replay::renderReplayFrames(s, models, dir, ro);
  ASSERT_EQ(r.frames.size(), 2u);
  ASSERT_EQ(r.bodyThrough.size(), 2u);
  ASSERT_EQ(r.frameNumbers.size(), 2u);
  EXPECT_GT(r.coveredTriangles, 500u);  // the mannequin's trunk under the jersey
  for (const replay::BodyThroughGarment& b : r.bodyThrough) {
    EXPECT_GT(b.garmentPixels, 500u);  // the jersey fills the framed picture
    EXPECT_LT(b.pixels, 96u * 128u - b.garmentPixels);
  }
  // Each frame that shows any has its copy with those pixels marked, and they share a sheet.
  size_t showing = 0;
  for (const replay::BodyThroughGarment& b : r.bodyThrough) showing += b.pixels > 0;
  EXPECT_EQ(r.throughFrames.size(), showing);
  for (const fs::path& f : r.throughFrames) EXPECT_TRUE(fs::exists(f)) << f;
  EXPECT_EQ(r.throughSheet.empty(), showing == 0);
  // No truth asked: no truth column.
  ASSERT_EQ(r.truthBodyThrough.size(), 2u);
  EXPECT_FALSE(r.truthBodyThrough[0] || r.truthBodyThrough[1]);
  const std::string md = replay::renderReportSection(r, ro, *tmp_ / "out");
  EXPECT_NE(md.find("Body through the garment"), std::string::npos) << md;
  EXPECT_NE(md.find("| frame | pixels | share of the garment's |\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| " + std::to_string(r.frameNumbers[1]) + " | " + std::to_string(r.bodyThrough[1].pixels) + " |"),
            std::string::npos)
      << md;
}

// With truth, the same measure on the truth's garment in the same pictures, beside the model's: whether the
// model or its source simulation puts the body through the cloth.
TEST_F(ReplayTruth, RenderMeasuresTheTruthsBodyThroughBesideTheModels) {
  const runtime::Scene s = scene(3, json::array({character("walker", true)}));
  replay::ModelLibrary models(s);
  replay::ReplayRenderOptions ro = smallPictures(1);
  ro.truth = cheaperTruth(2);
  ro.truth.normalMaps = false;
  const replay::ReplayRenderResult r = replay::renderReplayFrames(s, models, *tmp_ / "out/render_truth", ro);
  ASSERT_EQ(r.frames.size(), 1u);
  ASSERT_EQ(r.truthBodyThrough.size(), 1u);
  ASSERT_TRUE(r.truthBodyThrough[0].has_value()) << r.note;
  // The truth's jersey is drawn where the model's is: about as many garment pixels.
  EXPECT_NEAR(double(r.truthBodyThrough[0]->garmentPixels), double(r.bodyThrough[0].garmentPixels),
              0.2 * double(r.bodyThrough[0].garmentPixels));
  const std::string md = replay::renderReportSection(r, ro, *tmp_ / "out");
  EXPECT_NE(md.find("| frame | pixels | share of the garment's | truth pixels |"), std::string::npos) << md;
  EXPECT_NE(md.find("The truth (the source simulation's garment"), std::string::npos) << md;
  EXPECT_NE(md.find(" " + std::to_string(r.truthBodyThrough[0]->pixels) + " |\n"), std::string::npos) << md;
  // Where the truth shows the body, its pixels are painted on a copy of the frame, and the report shows the sheet.
  const bool truthShows = r.truthBodyThrough[0]->pixels > 0;
  ASSERT_EQ(r.truthThroughFrames.size(), truthShows ? 1u : 0u);
  EXPECT_EQ(r.truthThroughSheet.empty(), !truthShows);
  if (truthShows) {
    char name[48];
    std::snprintf(name, sizeof name, "truth_through_%04u.png", r.frameNumbers[0]);
    EXPECT_EQ(r.truthThroughFrames[0].filename(), name);
    EXPECT_TRUE(fs::exists(r.truthThroughFrames[0]));
    EXPECT_NE(md.find("truth_through_sheet.png"), std::string::npos) << md;
  }
}

// `--truth-cover-mm` and `--truth-limb-clearance-mm`: the truth is set up with them instead of the bake's, and
// its note says that it is overridden and how.
TEST_F(ReplayTruth, CoverAndLimbClearanceOverridesReachTheTruthAndAreSaid) {
  const runtime::Scene s = scene(1, json::array({character("walker", true)}));
  replay::ModelLibrary models(s);
  ASSERT_FALSE(models.entries().empty());
  replay::TruthOptions o = cheaperTruth(1);
  {
    const replay::ModelTruth t(*models.entries()[0], o);
    ASSERT_TRUE(t.available()) << t.note();
    EXPECT_EQ(t.note().find("cover_body_mm"), std::string::npos) << t.note();
  }
  o.coverBodyMm = 2.5f;
  o.limbClearanceMm = 0.f;
  {
    // The committed default model was baked with the cover in both poses: the override changes its margin.
    const replay::ModelTruth t(*models.entries()[0], o);
    ASSERT_TRUE(t.available()) << t.note();
    EXPECT_NE(t.note().find("overridden for this run (not the bake's): substeps cover_body_mm 2.5 limb clearance 0 mm"),
              std::string::npos)
        << t.note();
  }
  // A model baked before the cover ran in the recorded pose too (its settings lack cover_recorded_pose):
  // the override runs the cover as bakes run it today, in both poses, and says so.
  Model older = models.entries()[0]->model;
  json meta = json::parse(older.metadata);
  ASSERT_TRUE(meta["dataset_settings"]["transfer"].contains("cover_recorded_pose")) << meta["dataset_settings"].dump();
  meta["dataset_settings"]["transfer"].erase("cover_recorded_pose");
  older.metadata = meta.dump();
  saveModel(older, *tmp_ / "older.swish");
  json c = character("walker", true);
  c["model"] = (*tmp_ / "older.swish").string();
  const runtime::Scene so = scene(1, json::array({c}));
  replay::ModelLibrary olderModels(so);
  const replay::ModelTruth t(*olderModels.entries()[0], o);
  ASSERT_TRUE(t.available()) << t.note();
  EXPECT_NE(t.note().find("overridden for this run (not the bake's): substeps cover_body_mm 2.5 (in the recorded "
                          "pose too) limb clearance 0 mm"),
            std::string::npos)
      << t.note();
}

TEST_F(ReplayTruth, SameFiguresTwiceAndFarFromTheOrigin) {
  auto figures = [&](std::array<double, 3> at) {
    const replay::ReplayResult r = run(scene(3, json::array({character("walker", true, at)})), cheaperTruth(2));
    std::vector<double> v;
    for (const auto& f : r.frames)
      for (const auto& c : f.truth) v.insert(v.end(), {double(c.ok), c.meanMm, c.p95Mm, c.maxMm, c.meanDeg, c.maxDeg});
    v.insert(v.end(), {double(r.truthOverall.samples), r.truthOverall.meanMm, r.truthOverall.maxMm});
    return v;
  };
  const auto a = figures({0, 0, 0});
  ASSERT_EQ(a.size(), 2u * 6u + 3u);
  // Bitwise: the truth is simulated in character space, in parallel but each pose on one thread.
  EXPECT_EQ(a, figures({1e4, 0, -1e4}));
}

TEST_F(ReplayTruth, FramesOffScreenOrWithoutGpuWorkHaveNoTruth) {
  json c = character("hidden", false);
  c["visible"] = false;
  const replay::ReplayResult r = run(scene(2, json::array({c})), cheaperTruth(1));
  EXPECT_EQ(r.truthFrames, 0u);
  for (const auto& f : r.frames) EXPECT_TRUE(f.truth.empty());
  EXPECT_NE(r.truthNote.find("no GPU work"), std::string::npos) << r.truthNote;
}

// Models whose bake character cannot be rebuilt: a note saying why, no truth, no crash.
TEST(ReplayTruthNote, ModelsWithoutARebuildableCharacterSayWhy) {
  Rng rng(3);
  replay::ModelEntry e;
  e.key = "random";
  e.model = test::makeRandomModel(rng);
  const replay::TruthOptions o = cheaperTruth(1);
  {
    const replay::ModelTruth t(e, o);
    EXPECT_FALSE(t.available());
    EXPECT_NE(t.note().find("dataset_settings"), std::string::npos) << t.note();
  }
  e.model.metadata = R"({"dataset_settings": {"character": {"file": "/nonexistent/jersey.glb"}}})";
  {
    const replay::ModelTruth t(e, o);
    EXPECT_FALSE(t.available());
    EXPECT_NE(t.note().find("/nonexistent/jersey.glb is not at hand"), std::string::npos) << t.note();
  }
  // Settings of the embedded default character, but not its model: the character does not match.
  e.model.metadata = R"({"dataset_settings": {"character": {"file": "", "recipe": ""}}})";
  {
    const replay::ModelTruth t(e, o);
    EXPECT_FALSE(t.available());
    EXPECT_NE(t.note().find("is not the model's"), std::string::npos) << t.note();
  }
  e.procedural = true;
  {
    const replay::ModelTruth t(e, o);
    EXPECT_FALSE(t.available());
    EXPECT_NE(t.note().find("procedural"), std::string::npos) << t.note();
  }
}

TEST(ReplayTruthNote, ModelWithoutTruthReplaysWithTheNote) {
  std::string why;
  gpu::Context* ctx = test::sharedGpuContext(why);
  if (!ctx) GTEST_SKIP() << why;
  const test::TempDir tmp("truth_note");
  Rng rng(4);
  const Model m = test::makeRandomModel(rng);
  saveModel(m, tmp / "m.swish");
  replay::PoseStream st;
  for (const auto& j : m.skeleton.joints) st.joints.push_back(j.name);
  const Pose p = test::makeRandomPose(rng, m.skeleton);
  st.frames.push_back({p.rootTranslation, p.local, std::vector<bool>(p.local.size(), true)});
  replay::writePoseStream(tmp / "s.json", st);
  const json j{{"name", "n"},
               {"frames", {{"count", 3}}},
               {"outputs", {{"directory", "out"}}},
               {"characters", {{{"name", "a"}, {"model", "m.swish"}, {"poseStream", "s.json"}}}}};
  const runtime::Scene s = runtime::parseScene(j, tmp / "scene.json");
  replay::ModelLibrary lib(s);
  replay::ReplayOptions o;
  o.context = ctx;
  o.truth.every = 1;
  replay::ReplayEngine engine(s, lib, o);
  const replay::ReplayResult r = engine.run();
  EXPECT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.truthFrames, 0u);
  for (const auto& f : r.frames) EXPECT_FALSE(f.truthFrame);
  EXPECT_EQ(r.truthOverall.samples, 0u);
  EXPECT_NE(r.truthNote.find("no ground truth"), std::string::npos) << r.truthNote;
  const json rep = replay::reportJson(s, lib, r);
  EXPECT_EQ(rep["truth"]["overall"]["samples"], 0);
  EXPECT_FALSE(rep["truth"]["overall"].contains("meanMm"));
  EXPECT_FALSE(replay::reportMarkdown(rep).empty());
}

// The truth rebuilds the simulator from what the bake wrote: DatasetBuildSettings::toJson back to the
// same one-pose settings, and the committed default model's character rebuilt by code is its own.
TEST(ReplayTruthSettings, MetadataGivesBackTheBakeSettings) {
  bake::DatasetBuildSettings s;
  s.simulationVertices = 4321;
  s.simulation.material = bake::clothMaterialPreset("stiff");
  s.simulation.thickness = 0.006f;
  s.simulation.transitionSeconds = 0.7f;
  s.simulation.settleSeconds = 0.3f;
  s.simulation.frameRate = 45.f;
  s.simulation.substeps = 5;
  s.simulation.iterations = 3;
  s.simulation.gravity = Vec3f(0.f, -4.5f, 0.f);
  s.limbClearance.clearance = 0.02f;
  s.limbClearance.garmentReach = 0.04f;
  s.limbClearance.neckRangeDegrees = 75.f;
  s.simulation.attachTopFraction = 0.03f;
  s.transfer.smoothing.strength = 0.3f;
  s.transfer.smoothing.iterations = 5;
  s.transfer.smoothing.weights = bake::LaplacianWeights::Uniform;
  s.transfer.normalMap.width = s.transfer.normalMap.height = 128;
  s.transfer.normalMap.maxDistance = 0.02f;
  s.transfer.normalMap.dilationRings = 3;
  const bake::PoseShapeSettings a = s.poseShape();
  const bake::PoseShapeSettings b = bake::poseShapeSettingsFromJson(json::parse(s.toJson().dump()), "test");
  EXPECT_EQ(a.simulationVertices, b.simulationVertices);
  EXPECT_EQ(a.simulation.material.name, b.simulation.material.name);
  EXPECT_EQ(a.simulation.material.stretchModulus, b.simulation.material.stretchModulus);
  EXPECT_EQ(a.simulation.thickness, b.simulation.thickness);
  EXPECT_EQ(a.simulation.transitionSeconds, b.simulation.transitionSeconds);
  EXPECT_EQ(a.simulation.settleSeconds, b.simulation.settleSeconds);
  EXPECT_EQ(a.simulation.frameRate, b.simulation.frameRate);
  EXPECT_EQ(a.simulation.substeps, b.simulation.substeps);
  EXPECT_EQ(a.simulation.iterations, b.simulation.iterations);
  EXPECT_EQ(a.simulation.gravity, b.simulation.gravity);
  EXPECT_EQ(a.limbClearance.clearance, b.limbClearance.clearance);
  EXPECT_EQ(a.limbClearance.garmentReach, b.limbClearance.garmentReach);
  EXPECT_EQ(a.limbClearance.neckRangeDegrees, b.limbClearance.neckRangeDegrees);
  // A model baked before the clearance looked only under the garment kept the whole trunk clear.
  json old = json::parse(s.toJson().dump());
  old["simulation"].erase("limb_garment_reach");
  EXPECT_EQ(bake::poseShapeSettingsFromJson(old, "test").limbClearance.garmentReach, 0.f);
  // A model baked before the neck range: its truth leaves the neck as recorded.
  old["simulation"].erase("limb_neck_range");
  EXPECT_EQ(bake::poseShapeSettingsFromJson(old, "test").limbClearance.neckRangeDegrees, 0.f);
  EXPECT_EQ(a.simulation.attachTopFraction, b.simulation.attachTopFraction);
  EXPECT_EQ(a.transfer.smoothing.strength, b.transfer.smoothing.strength);
  EXPECT_EQ(a.transfer.smoothing.iterations, b.transfer.smoothing.iterations);
  EXPECT_EQ(a.transfer.smoothing.weights, b.transfer.smoothing.weights);
  EXPECT_EQ(a.transfer.normalMap.width, b.transfer.normalMap.width);
  EXPECT_EQ(a.transfer.normalMap.height, b.transfer.normalMap.height);
  EXPECT_EQ(a.transfer.normalMap.maxDistance, b.transfer.normalMap.maxDistance);
  EXPECT_EQ(a.transfer.normalMap.dilationRings, b.transfer.normalMap.dilationRings);
  EXPECT_EQ(a.transfer.cover.margin, b.transfer.cover.margin);

  EXPECT_NE(test::errorOf([] {
              bake::poseShapeSettingsFromJson(json::parse(R"({"simulation": {"substeps": "8"}})"), "meta");
            }).find("meta.simulation.substeps"),
            std::string::npos);

  if (!fs::exists(defaultModelFile())) GTEST_SKIP() << "no committed default model";
  const Model m = loadModel(defaultModelFile());
  Character c = bake::makeDefaultCharacter();
  EXPECT_EQ(replay::characterDifference(m, c), "");
  c.garment.positions(7, 1) += 0.001f;
  EXPECT_EQ(replay::characterDifference(m, c), "the game mesh's rest positions differ");
}

}  // namespace
