// swish replay end to end on a small seeded model (3 characters, a few frames): the report is written
// and parses, figures repeat exactly, bad poses are reported with frame and character while the other
// characters go on, a character at 1e4 m gets the local mesh it gets at the origin, leaving normal maps
// out keeps the meshes unchanged, the planner's memory is the memory really allocated, and an error
// leaves no partial outputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include "support/error_message.hpp"
#include "support/gpu_test.hpp"
#include "support/paths.hpp"
#include "support/random_model.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/error.hpp"
#include "swish/gpu/allocation_plan.hpp"
#include "swish/gpu/frame_recorder.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/replay_job.hpp"
#include "swish/replay/replay_plan.hpp"
#include "swish/replay/replay_render.hpp"
#include "swish/replay/report_writer.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/scene_file.hpp"

namespace {

using namespace swish;
namespace fs = std::filesystem;
using nlohmann::json;

class ReplayE2E : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    dir_ = tmp_.emplace("replay_e2e").path();
    const uint64_t seed = test::announcedTestSeed(11);
    Rng rng(seed);
    test::RandomModelSpec spec;
    spec.joints = 8;
    spec.vertices = 120;
    spec.normalMaps = 4;
    spec.mapSize = 16;
    spec.bodyAnchors = true;    // the push-out runs, and the GPU-vs-CPU checks cover it
    spec.secondAnchors = true;  // both anchor sets (BodyAnchors::second)
    spec.noveltyCentres = 5;    // the novelty guard runs, and the checks cover its weights too
    model_ = test::makeRandomModel(rng, spec);
    // What the bake records of its evaluation on held-out poses (part2_training.cpp).
    model_.metadata =
        R"({"errors": {"held_out_poses": 7, "vertex_total": {"mean_mm": 1.5, "p95_mm": 3, "max_mm": 4}}})";
    saveModel(model_, dir_ / "m.swish");
    writeStream("walk.json", rng, 6, {});
  }
  void TearDown() override {
    tmp_.reset();
    test::GpuTest::TearDown();
  }

  // A pose stream of `frames` random poses; `edit` may spoil some.
  void writeStream(const std::string& name, Rng& rng, int frames,
                   const std::function<void(replay::PoseStream&)>& edit) {
    replay::PoseStream s;
    s.framesPerSecond = 30;
    for (const auto& j : model_.skeleton.joints) s.joints.push_back(j.name);
    for (int f = 0; f < frames; ++f) {
      const Pose p = test::makeRandomPose(rng, model_.skeleton, 0.6f);
      replay::PoseStreamFrame fr;
      fr.root = p.rootTranslation;
      fr.rotations = p.local;
      fr.present.assign(p.local.size(), true);
      s.frames.push_back(fr);
    }
    if (edit) edit(s);
    replay::writePoseStream(dir_ / name, s);
  }

  json sceneJson(const std::vector<std::string>& streams) const {
    json j{{"name", "e2e"},
           {"frames", {{"count", 5}, {"rate", 30}}},
           {"outputs", {{"directory", "out"}, {"render", true}, {"gpuCheckEvery", 2}}}};
    for (size_t i = 0; i < streams.size(); ++i) {
      std::string name = "c";  // (not "c" + to_string: GCC 12's false -Wrestrict, bug 105329)
      name += std::to_string(i);
      j["characters"].push_back(
          {{"name", name},
           {"model", "m.swish"},
           {"poseStream", streams[i]},
           {"placement", {{"translation", {double(i), 0.0, 0.0}}, {"yawDegrees", 30.0 * double(i)}}}});
    }
    return j;
  }
  runtime::Scene scene(const json& j) const { return runtime::parseScene(j, dir_ / "scene.json"); }

  replay::ReplayJobOptions jobOptions() {
    replay::ReplayJobOptions o;
    o.quiet = true;
    o.engine.context = &ctx();
    o.engine.pushOut = true;  // the model carries anchors: the GPU-vs-CPU checks cover the push-out step
    return o;
  }

  std::optional<test::TempDir> tmp_;  // made in SetUp, only when the test runs
  fs::path dir_;
  Model model_;
};

// `swish replay --render`: PNG frames and a contact sheet, and the report's section says what they show
// (the push-out, the body drawn whole or without its covered triangles; here no body at all: the
// random model's skeleton is not the mannequin's, and the note says so).
TEST_F(ReplayE2E, RenderDrawsFramesAContactSheetAndSaysWhatTheyShow) {
  auto has = [](const std::string& text, const char* part) { return text.find(part) != std::string::npos; };
  const runtime::Scene s = scene(sceneJson({"walk.json"}));
  replay::ModelLibrary models(s);
  replay::ReplayRenderOptions ro;
  ro.maxFrames = 2;
  ro.width = 64;
  ro.height = 80;
  ro.validation = true;  // any message fails the render
  ro.pushOut = true;
  ro.hideCoveredBody = true;
  const fs::path dir = dir_ / "out/render";
  const replay::ReplayRenderResult r = replay::renderReplayFrames(s, models, dir, ro);
  ASSERT_EQ(r.frames.size(), 2u);
  for (const fs::path& f : r.frames) {
    // Each frame at the asked size (`swish replay --render-size`): the PNG header's width and height.
    std::ifstream png(f, std::ios::binary);
    unsigned char header[24] = {};
    ASSERT_TRUE(png.read(reinterpret_cast<char*>(header), sizeof header)) << f;
    auto be32 = [&](int at) {
      return uint32_t(header[at]) << 24 | uint32_t(header[at + 1]) << 16 | uint32_t(header[at + 2]) << 8 |
             header[at + 3];
    };
    EXPECT_EQ(be32(16), 64u) << f;
    EXPECT_EQ(be32(20), 80u) << f;
  }
  EXPECT_EQ(r.contactSheet, dir / "contact_sheet.png");
  EXPECT_TRUE(fs::exists(r.contactSheet));
  EXPECT_TRUE(r.heatSheet.empty());
  EXPECT_TRUE(has(r.note, "no mannequin drawn")) << r.note;
  EXPECT_TRUE(r.bodyThrough.empty());  // no body drawn, nothing to measure
  const std::string md = replay::renderReportSection(r, ro, dir_ / "out");
  EXPECT_TRUE(has(md, "## Pictures")) << md;
  EXPECT_TRUE(has(md, "push-out was ON")) << md;
  EXPECT_TRUE(has(md, "without the triangles the garment covers")) << md;
  EXPECT_TRUE(has(md, "![contact sheet](render/contact_sheet.png)")) << md;
  ro.pushOut = false;
  ro.hideCoveredBody = false;
  const std::string whole = replay::renderReportSection(r, ro, dir_ / "out");
  EXPECT_TRUE(has(whole, "push-out was OFF")) << whole;
  EXPECT_TRUE(has(whole, "drawn whole")) << whole;
  // A character the scene does not have is an error naming it, and leaves no render folder behind.
  ro.character = 5;
  const std::string bad = test::errorOf([&] { replay::renderReplayFrames(s, models, dir_ / "bad", ro); });
  EXPECT_TRUE(has(bad, "--render character 5 but the scene has 1 characters")) << bad;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

TEST_F(ReplayE2E, WritesAReportThatParsesWithErrorBesideTime) {
  const runtime::Scene s = scene(sceneJson({"walk.json", "walk.json", "walk.json"}));
  const auto r = replay::runReplayJob(s, jobOptions());
  EXPECT_FALSE(r.result.failed()) << (r.result.failures.empty() ? "" : r.result.failures[0]);
  ASSERT_EQ(r.directory, dir_ / "out");
  std::ifstream in(dir_ / "out/report.json");
  const json rep = json::parse(in);
  EXPECT_EQ(rep["summary"]["frames"], 5);
  EXPECT_EQ(rep["summary"]["checkedFrames"], 3);  // frames 0, 2, 4
  EXPECT_EQ(rep["characters"].size(), 3u);
  EXPECT_EQ(rep["plan"]["gpuDispatchesPerFrame"], 5);
  // The plan's count is what the recorder records: all of it on frame 0 (every selected map is new),
  // never more on a later frame (no VQ decode where the selected maps were decoded before).
  ASSERT_EQ(rep["frames"].size(), 5u);
  EXPECT_EQ(rep["frames"][0]["gpuDispatches"], 5);
  for (const auto& f : rep["frames"]) EXPECT_LE(f["gpuDispatches"].get<int>(), 5) << f["frame"];
  EXPECT_LE(rep["summary"]["gpuVsCpu"]["maxPositionErrorMm"].get<double>(), replay::kPositionToleranceMm);
  EXPECT_LE(rep["summary"]["gpuVsCpu"]["maxMapErrorSteps"].get<int>(), replay::kMapToleranceSteps);
  EXPECT_TRUE(rep["frames"][0]["times"]["gpuDeform"].is_number());
  EXPECT_EQ(rep["models"][0]["heldOutErrors"]["held_out_poses"], 7);
  EXPECT_TRUE(rep["truth"]["available"].get<bool>());
  // No bake character behind a random model: penetration is not measured, and the report says why.
  EXPECT_NE(rep["penetration"]["note"].get<std::string>().find("not measured"), std::string::npos)
      << rep["penetration"];
  EXPECT_TRUE(rep["penetration"]["pushOut"].get<bool>());
  EXPECT_FALSE(rep["penetration"].contains("overall"));
  std::ifstream md(dir_ / "out/report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("7 held-out poses, simulated): vertex error mean 1.5 mm, p95 3 mm"), std::string::npos) << text;
  EXPECT_TRUE(rep["frames"][0]["gpuVsCpu"]["maxPositionErrorMm"].is_number());
  for (const char* f : {"report.md", "plots/time_per_frame.svg", "plots/time_per_stage.svg",
                        "plots/error_per_frame.svg", "plots/error_vs_time.svg"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().string().find(".partial-"), std::string::npos);
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

// Quality levels: every character at a fixed level passes the GPU-vs-CPU checks and reads no more
// than its components; a budget below every level's cost steps everyone to the cheapest and says so;
// the report carries the ladder, the levels per frame and the characters' changes.
TEST_F(ReplayE2E, QualityLevelsFixedAndBudgeted) {
  const runtime::QualityLadder ladder = runtime::ladderOf(model_);
  ASSERT_GE(ladder.size(), 3u);
  for (size_t l = 0; l < ladder.size(); ++l) {
    runtime::Scene s = scene(sceneJson({"walk.json", "walk.json", "walk.json"}));
    s.outputs.directory = dir_ / ("level" + std::to_string(l));
    auto o = jobOptions();
    o.engine.fixedLevel = ladder[l].name;
    const auto r = replay::runReplayJob(s, o);
    EXPECT_FALSE(r.result.failed()) << ladder[l].name << ": "
                                    << (r.result.failures.empty() ? "" : r.result.failures[0]);
    for (const auto& f : r.result.frames) {
      ASSERT_EQ(f.levels.size(), 3u);
      for (uint8_t v : f.levels) EXPECT_EQ(v, l);
      EXPECT_EQ(f.levelChanges, 0u);
      if (!ladder[l].normalMaps) {
        EXPECT_LE(f.gpuDispatches, 3u) << "no decode or blend without maps";
      }
    }
  }
  runtime::Scene s = scene(sceneJson({"walk.json", "walk.json", "walk.json"}));
  s.levels.frameBudgetMs = 1e-6;  // below anything: everyone at the cheapest level
  s.outputs.directory = dir_ / "budget";
  const auto r = replay::runReplayJob(s, jobOptions());
  EXPECT_FALSE(r.result.failed()) << (r.result.failures.empty() ? "" : r.result.failures[0]);
  ASSERT_EQ(r.result.levels.size(), 1u);
  EXPECT_NE(r.result.levelCostsSource.find("calibrated on"), std::string::npos) << r.result.levelCostsSource;
  ASSERT_EQ(r.result.levels[0].calibratedMsPerCharacter.size(), ladder.size());
  // Everyone steps down to the first level with the cheapest calibrated cost (levels that measured no
  // cheaper than one before them save nothing: on this tiny model, under a loaded machine, that may be
  // level 0 itself; the planner's own tests hold the descent to exact costs), and every frame is over
  // the budget.
  const auto& costs = r.result.levels[0].calibratedMsPerCharacter;
  const double cheapest = *std::min_element(costs.begin(), costs.end());
  for (size_t f = 1; f < r.result.frames.size(); ++f)
    for (uint8_t v : r.result.frames[f].levels)
      EXPECT_LE(*std::min_element(costs.begin(), costs.begin() + v + 1), cheapest) << "frame " << f;
  std::ifstream in(dir_ / "budget/report.json");
  const json rep = json::parse(in);
  ASSERT_TRUE(rep.contains("levels"));
  EXPECT_EQ(rep["levels"]["models"][0]["ladder"]["levels"].size(), ladder.size());
  EXPECT_EQ(rep["levels"]["characters"].size(), 3u);
  EXPECT_LE(rep["levels"]["characters"][0]["maxChangesPerSecond"].get<int>(), 1);
  EXPECT_EQ(rep["levels"]["summary"]["framesOverBudget"], r.result.frames.size());
  EXPECT_TRUE(rep["frames"][1]["levels"].is_array());
  EXPECT_TRUE(fs::exists(dir_ / "budget/plots/levels_per_frame.svg"));
  std::ifstream md(dir_ / "budget/report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("## Quality levels"), std::string::npos);
  EXPECT_NE(text.find("frame budget of 1e-06 GPU ms"), std::string::npos) << text.substr(text.find("## Quality"), 400);
  runtime::Scene bad = scene(sceneJson({"walk.json"}));
  auto o = jobOptions();
  o.engine.fixedLevel = "k999";
  EXPECT_NE(test::errorOf([&] { replay::runReplayJob(bad, o); }).find("no level 'k999'"), std::string::npos);
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

// Novelty per character per frame in report.json (the flag agreeing with the model's threshold), a plot,
// a section in report.md; --no-guard measures the same novelty and changes the weights where the guard
// clamped them.
TEST_F(ReplayE2E, ReportsNoveltyPerCharacterAndFlagsFrames) {
  const runtime::Scene s = scene(sceneJson({"walk.json", "walk.json"}));
  auto o = jobOptions();
  std::vector<float> withGuard, withoutGuard;
  o.engine.onCharacterOutput = [&](uint32_t, uint32_t, const runtime::ReferenceFrameOutputs& out, uint32_t i) {
    for (Eigen::Index v = 0; v < out.positions[i].rows(); ++v) withGuard.push_back(out.positions[i](v, 0));
  };
  const auto r = replay::runReplayJob(s, o);
  EXPECT_FALSE(r.result.failed()) << (r.result.failures.empty() ? "" : r.result.failures[0]);
  const json rep = json::parse(std::ifstream(dir_ / "out/report.json"));
  const json& nv = rep["novelty"];
  EXPECT_TRUE(nv["measured"].get<bool>());
  EXPECT_TRUE(nv["guard"].get<bool>());
  EXPECT_EQ(nv["characterFrames"], 10);
  size_t flagged = 0;
  std::vector<float> novelty;
  for (const auto& f : rep["frames"]) {
    ASSERT_EQ(f["novelty"].size(), 2u) << f["frame"];
    for (const auto& c : f["novelty"]) {
      const float v = c["novelty"].get<float>();
      novelty.push_back(v);
      EXPECT_GT(v, 0.f);
      EXPECT_EQ(c["flagged"].get<bool>(), v > model_.noveltyGuard.flagAbove);
      flagged += c["flagged"].get<bool>();
    }
  }
  EXPECT_EQ(nv["flaggedCharacterFrames"].get<size_t>(), flagged);
  EXPECT_EQ(rep["characters"][0]["novelty"]["framesFlagged"].get<size_t>() +
                rep["characters"][1]["novelty"]["framesFlagged"].get<size_t>(),
            flagged);
  EXPECT_TRUE(fs::exists(dir_ / "out/plots/novelty_per_frame.svg"));
  const std::string md = [&] {
    std::ifstream in(dir_ / "out/report.md");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }();
  EXPECT_NE(md.find("## Novelty"), std::string::npos);

  o.engine.noveltyGuard = false;
  o.engine.onCharacterOutput = [&](uint32_t, uint32_t, const runtime::ReferenceFrameOutputs& out, uint32_t i) {
    for (Eigen::Index v = 0; v < out.positions[i].rows(); ++v) withoutGuard.push_back(out.positions[i](v, 0));
  };
  const auto off = replay::runReplayJob(s, o);
  EXPECT_FALSE(off.result.failed());
  const json repOff = json::parse(std::ifstream(dir_ / "out/report.json"));
  EXPECT_FALSE(repOff["novelty"]["guard"].get<bool>());
  size_t k = 0;
  for (const auto& f : repOff["frames"])
    for (const auto& c : f["novelty"]) EXPECT_EQ(c["novelty"].get<float>(), novelty[k++]);
  // The random network's weights leave the random ranges (clamped): the meshes differ somewhere.
  ASSERT_EQ(withGuard.size(), withoutGuard.size());
  EXPECT_NE(withGuard, withoutGuard);
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

TEST_F(ReplayE2E, SameSceneGivesTheSameFigures) {
  const runtime::Scene s = scene(sceneJson({"walk.json", "walk.json"}));
  auto figures = [&] {
    replay::ModelLibrary lib(s);
    replay::ReplayOptions o;
    o.context = &ctx();
    replay::ReplayEngine engine(s, lib, o);
    json j = replay::reportJson(s, lib, engine.run());
    json keep{{"characters", j["characters"]}, {"plan", j["plan"]}, {"summaryErrors", j["summary"]["gpuVsCpu"]}};
    for (auto& f : j["frames"]) keep["frames"].push_back(f.value("gpuVsCpu", json()));
    return keep;
  };
  EXPECT_EQ(figures(), figures());
}

TEST_F(ReplayE2E, BadPosesAreReportedAndTheOthersGoOn) {
  Rng rng(5);
  writeStream("bad.json", rng, 6, [](replay::PoseStream& s) {
    s.frames[1].rotations[2] = Quatf(std::numeric_limits<float>::quiet_NaN(), 0, 0, 0);
    s.frames[2].rotations[3] = Quatf(2.f, 0, 0, 0);
    s.frames[3].present[1] = false;
  });
  const runtime::Scene s = scene(sceneJson({"walk.json", "bad.json", "walk.json"}));
  replay::ModelLibrary lib(s);
  replay::ReplayOptions o;
  o.context = &ctx();
  replay::ReplayEngine engine(s, lib, o);
  const auto r = engine.run();
  EXPECT_TRUE(r.failed());
  ASSERT_EQ(r.issueCount, 3u);
  for (const auto& i : r.issues) EXPECT_EQ(i.character, "c1");
  EXPECT_EQ(r.issues[0].frame, 1u);
  EXPECT_EQ(r.issues[0].joint, model_.skeleton.joints[2].name);
  EXPECT_EQ(r.issues[0].action, "rest rotation");
  EXPECT_EQ(r.issues[1].frame, 2u);
  EXPECT_EQ(r.issues[1].action, "normalised");
  EXPECT_EQ(r.issues[2].frame, 3u);
  EXPECT_NE(r.issues[2].problem.find("missing"), std::string::npos);
  ASSERT_EQ(r.frames.size(), 5u);
  for (const auto& f : r.frames)
    for (const auto& c : f.checks) EXPECT_TRUE(c.ok) << "frame " << f.frame << " character " << c.character;
  EXPECT_TRUE(r.failures.empty());
}

TEST_F(ReplayE2E, FarFromTheOriginTheLocalMeshIsTheSame) {
  json j = sceneJson({"walk.json", "walk.json"});
  j["characters"][1]["placement"] = {{"translation", {1e4, 0.0, -1e4}}, {"yawDegrees", 0.0}};
  j["characters"][0]["placement"] = {{"translation", {0.0, 0.0, 0.0}}, {"yawDegrees", 0.0}};
  const runtime::Scene s = scene(j);
  replay::ModelLibrary lib(s);
  replay::ReplayOptions o;
  o.context = &ctx();
  std::map<std::pair<uint32_t, uint32_t>, Points3f> local;
  o.onCharacterOutput = [&](uint32_t frame, uint32_t c, const runtime::ReferenceFrameOutputs& out, uint32_t i) {
    local[{frame, c}] = out.positions[i];
  };
  replay::ReplayEngine engine(s, lib, o);
  engine.run();
  ASSERT_EQ(local.size(), 10u);
  for (uint32_t f = 0; f < 5; ++f) {
    const Points3f& a = local[{f, 0}];
    const Points3f& b = local[{f, 1}];
    ASSERT_EQ(a.rows(), b.rows());
    EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.f) << "frame " << f;
    // World positions in double keep the local detail at 1e4 m (float world coordinates would not:
    // their spacing there is about 1 mm).
    const auto& place = s.characters[1].placement;
    for (Eigen::Index v = 0; v < b.rows(); ++v)
      EXPECT_NEAR((place.apply(b.row(v).transpose()) - place.translation - b.row(v).transpose().cast<double>()).norm(),
                  0.0, 1e-9);
  }
}

TEST_F(ReplayE2E, LeavingNormalMapsOutKeepsTheMeshes) {
  json full = sceneJson({"walk.json", "walk.json"});
  json lean = full;
  lean["outputs"]["render"] = false;
  lean["outputs"]["meshes"] = true;
  auto positions = [&](const runtime::Scene& s, replay::ReplayPlan* plan) {
    replay::ModelLibrary lib(s);
    replay::ReplayOptions o;
    o.context = &ctx();
    std::vector<Points3f> out;
    o.onCharacterOutput = [&](uint32_t, uint32_t, const runtime::ReferenceFrameOutputs& r, uint32_t i) {
      out.push_back(r.positions[i]);
    };
    replay::ReplayEngine engine(s, lib, o);
    *plan = engine.plan();
    const replay::ReplayResult r = engine.run();
    // What was recorded is what was planned: all of it on frame 0, never more later.
    EXPECT_EQ(r.frames.front().gpuDispatches, plan->gpuDispatchesPerFrame());
    for (const auto& f : r.frames) EXPECT_LE(f.gpuDispatches, plan->gpuDispatchesPerFrame()) << f.frame;
    return out;
  };
  replay::ReplayPlan pFull, pLean;
  const auto a = positions(scene(full), &pFull);
  const auto b = positions(scene(lean), &pLean);
  EXPECT_EQ(pFull.gpuDispatchesPerFrame(), 5u);
  EXPECT_EQ(pLean.gpuDispatchesPerFrame(), 1u);
  EXPECT_LT(pLean.gpuBytes(), pFull.gpuBytes());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ((a[i] - b[i]).cwiseAbs().maxCoeff(), 0.f) << i;
}

// The plan's memory is what the GPU side allocates, buffer by buffer (name and bytes): the planner
// asks gpu::modelAllocations / frameAllocations, and GpuModel / FrameResources size their buffers
// with the same code. Body anchors add the model's anchor buffer (and nothing per frame).
TEST_F(ReplayE2E, PlannedMemoryIsAllocatedMemory) {
  struct Case {
    bool maps, proxy;
  };
  for (const Case k : {Case{true, false}, Case{false, false}, Case{true, true}, Case{false, true}}) {
    SCOPED_TRACE("maps " + std::to_string(k.maps) + ", proxy " + std::to_string(k.proxy));
    Model m = model_;
    if (!k.maps) m.normalMaps = NormalMapDatabase{};
    if (!k.proxy) {
      m.bodyAnchors = BodyAnchors{};
    } else if (m.bodyAnchors.empty()) {
      BodyAnchor a;
      a.normal = Vec3f::UnitZ();
      a.radius = 0.05f;
      a.clearance = 0.002f;
      a.weights = {1.f, 0.f, 0.f, 0.f};
      m.bodyAnchors.anchors.assign(m.gameMesh.vertexCount(), a);
    }
    gpu::GpuModel g(ctx(), m, "m");
    gpu::FrameRecorderOptions ro;
    ro.framesInFlight = 1;
    ro.normalMaps = ro.tangentFrames = k.maps;
    gpu::FrameRecorder rec(ctx(), g, 3, ro);
    // What was allocated: name (without its "<owner>: " prefix) -> bytes.
    auto allocated = [](std::initializer_list<const gpu::Buffer*> buffers, const std::string& prefix) {
      std::map<std::string, uint64_t> out;
      for (const gpu::Buffer* b : buffers) {
        if (!b->handle()) continue;  // not allocated (no maps, no proxy, or texels shared with the images)
        EXPECT_EQ(b->name().rfind(prefix, 0), 0u) << b->name();
        out[b->name().substr(prefix.size())] = b->size();
      }
      return out;
    };
    auto planned = [](const std::vector<gpu::Allocation>& list, bool images) {
      std::map<std::string, uint64_t> out;
      for (const auto& a : list)
        if (a.image == images) out[a.name] = a.bytes;
      return out;
    };
    EXPECT_EQ(allocated({&g.mean, &g.basis, &g.skinJoints, &g.skinWeights, &g.uvs, &g.triangles, &g.normalOffsets,
                         &g.normalTriangles, &g.tangentOffsets, &g.tangentTriangles, &g.frameTriangles, &g.codebook,
                         &g.indices, &g.anchors},
                        "m: "),
              planned(gpu::modelAllocations(m, k.maps), false));
    const auto& f = rec.frame(0);
    // Shared texels need a device that samples linear 2D arrays (and lays them out tightly): lavapipe does.
    const bool shared = k.maps && f.normalMaps.sharesTexels();
    if (shared) {
      EXPECT_TRUE(gpu::NormalMapImages::deviceSupportsLinear(ctx(), f.normalMaps.width(), f.normalMaps.height(), 3));
    }
    if (k.maps && ctx().deviceName().find("llvmpipe") != std::string::npos) {
      EXPECT_TRUE(shared);
    }
    const auto plan = gpu::frameAllocations(m, 3, k.maps, k.maps, shared);
    EXPECT_EQ(allocated({&f.meshWeights, &f.instanceOrder, &f.skinMatrices, &f.decodeSlotMaps, &f.blendCharacters,
                         &f.positions, &f.normals, &f.tangents, &f.triangleTerms, &f.decodedMaps, &f.blendedTexels},
                        "m frame 0: "),
              planned(plan, false));
    uint64_t imageBytes = 0;
    for (const auto& [name, bytes] : planned(plan, true)) imageBytes += bytes;
    EXPECT_EQ(imageBytes,
              k.maps ? uint64_t(f.normalMaps.width()) * f.normalMaps.height() * f.normalMaps.layers() * 4 : 0u);
    EXPECT_EQ(planned(gpu::modelAllocations(m, k.maps), false).count("body anchors"), k.proxy ? 1u : 0u);
  }
}

TEST_F(ReplayE2E, WritesPerFrameMeshesAndNormalMaps) {
  json j = sceneJson({"walk.json", "walk.json"});
  j["outputs"]["meshes"] = true;
  j["outputs"]["normalMaps"] = true;
  j["characters"][1]["placement"] = {{"translation", {1e4, 0.0, 0.0}}, {"yawDegrees", 90.0}};
  const auto r = replay::runReplayJob(scene(j), jobOptions());
  EXPECT_FALSE(r.result.failed());
  for (int f = 0; f < 5; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "meshes/frame_%06d.gltf", f);
    std::ifstream in(dir_ / "out" / name);
    ASSERT_TRUE(in) << name;
    const json g = json::parse(in);
    ASSERT_EQ(g["meshes"].size(), 2u);
    EXPECT_EQ(g["accessors"][0]["count"], model_.gameMesh.vertexCount());
    EXPECT_EQ(g["nodes"][1]["translation"][0].get<double>(), 1e4);  // placement on the node, mesh local
    std::snprintf(name, sizeof name, "normal_maps/c1_%06d.png", f);
    EXPECT_TRUE(fs::exists(dir_ / "out" / name)) << name;
  }
}

// A clip on another skeleton (the Daz-rig CMU conversion, ../shared/mocap/cmu-daz) plays on the default
// model through the joint map its scene entry names; without it the scene stops, naming the character
// and asking for the pairs.
TEST_F(ReplayE2E, AClipWithOtherJointNamesPlaysThroughItsJointMap) {
  const fs::path clip = test::sharedMocap("cmu-daz/10_04.bvh");
  if (!fs::exists(clip)) {
    if (std::getenv("CI")) FAIL() << clip << " is absent in CI";
    GTEST_SKIP() << clip << " is absent (the shared mocap corpus)";
  }
  const fs::path map = test::sourceDir() / "assets/joint_maps/cmu_daz.json";
  json j{{"name", "daz"}, {"frames", {{"count", 3}, {"rate", 30}}}, {"outputs", {{"directory", "out"}}}};
  j["characters"].push_back(
      {{"name", "walker"},
       {"model", "default"},
       {"animation", {{"file", clip.string()}, {"timeOffset", 1.0}, {"jointMap", map.string()}}}});
  const auto r = replay::runReplayJob(scene(j), jobOptions());
  EXPECT_FALSE(r.result.failed()) << (r.result.failures.empty() ? "" : r.result.failures[0]);
  const json rep = json::parse(std::ifstream(dir_ / "out/report.json"));
  EXPECT_EQ(rep["summary"]["frames"], 3);
  EXPECT_LE(rep["summary"]["gpuVsCpu"]["maxPositionErrorMm"].get<double>(), replay::kPositionToleranceMm);

  j["characters"][0]["animation"].erase("jointMap");
  j["outputs"]["directory"] = "out2";
  try {
    replay::runReplayJob(scene(j), jobOptions());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("characters[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("add pairs to the joint map"), std::string::npos) << e.what();
  }
  // A malformed inline map is named by its JSON path.
  j["characters"][0]["animation"]["jointMap"] = {{"chest", {{"joints", {"Spine", "Spine1"}}, {"shares", {0.9, 0.9}}}}};
  try {
    replay::runReplayJob(scene(j), jobOptions());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("characters[0].animation.jointMap.chest.shares"), std::string::npos)
        << e.what();
  }
  // The same map in a file is named by the file and the path inside it (not "<file>.chest.shares").
  std::ofstream(dir_ / "bad_map.json") << j["characters"][0]["animation"]["jointMap"].dump();
  j["characters"][0]["animation"]["jointMap"] = (dir_ / "bad_map.json").string();
  try {
    replay::runReplayJob(scene(j), jobOptions());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad_map.json: chest.shares"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

// The replay replaces its output folder whole: a folder with anything no replay wrote (a log beside it, a
// home folder given as --out) is refused before any work and left as it was; its own earlier output, and an
// empty folder, are replaced.
TEST_F(ReplayE2E, AnOutputFolderWithOtherFilesIsRefusedNotDeleted) {
  const runtime::Scene s = scene(sceneJson({"walk.json"}));
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "out" / "notes.txt") << "mine";
  const std::string e = test::errorOf([&] { replay::runReplayJob(s, jobOptions()); });
  EXPECT_NE(e.find("holds 'notes.txt', which no replay wrote"), std::string::npos) << e;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "notes.txt"));
  fs::remove(dir_ / "out" / "notes.txt");
  replay::runReplayJob(s, jobOptions());  // an empty folder
  EXPECT_TRUE(fs::exists(dir_ / "out" / "report.json"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / ".swish-replay"));
  fs::create_directories(dir_ / "out" / "render");
  std::ofstream(dir_ / "out" / "render" / "frame.png") << "x";
  replay::runReplayJob(s, jobOptions());  // its own output: replaced
  EXPECT_FALSE(fs::exists(dir_ / "out" / "render" / "frame.png"));
  std::ofstream(dir_ / "file") << "x";
  runtime::Scene toFile = s;
  toFile.outputs.directory = dir_ / "file";
  EXPECT_NE(test::errorOf([&] { replay::runReplayJob(toFile, jobOptions()); }).find("is a file"), std::string::npos);
  EXPECT_EQ(ctx().validationMessageCount(), 0u);
}

TEST_F(ReplayE2E, AnErrorLeavesNoPartialOutputs) {
  std::ofstream(dir_ / "broken.json") << "{ \"format\": \"swish-pose-stream\", \"version\": 1, \"joints\": [";
  const runtime::Scene s = scene(sceneJson({"walk.json", "broken.json"}));
  try {
    replay::runReplayJob(s, jobOptions());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("characters[1]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("broken.json"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().string().find(".partial-"), std::string::npos);
}

}  // namespace
