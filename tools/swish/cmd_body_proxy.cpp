// swish body-proxy MODEL [--out OUT]: fits the body anchors of the run-time push-out
// (bake/training/body_anchor_fit.hpp: per garment vertex, the closest point of the rest body, its
// outward normal and its skin) to the body the model was baked on, and writes the model with them
// (format 1.3; the second set 1.4, the third 1.5). `swish bake` fits them itself; this is for a model baked before they
// existed: nothing else in the model changes, and the network is not retrained. `--remove` writes the model without
// them (no push-out at run time).
//
// `--clips` calibrates the anchors as the bake does on its training poses (calibrateBodyAnchors): the
// model's garment against the bake's source simulation (replay/truth_simulation.hpp, as `swish replay
// --truth-every` runs it) of `--poses` frames of those clips, in parallel, about 4 s of CPU each with
// the default model. Without it every anchor keeps the bare margin, which pushes against the
// simulation where it puts the garment inside the ball (cloth squeezed between arm and trunk): it may raise the
// vertex error a little (measure it with `swish replay --truth-every N --push-out`).
//
// The body is rebuilt as `swish replay --truth-every` rebuilds it, from the model's own bake metadata
// (the embedded default character by code, or the recipe/character file it names, looked for as
// written and beside the model), and checked to match the model's skeleton, game mesh and skin. A
// model whose bake character cannot be rebuilt gets a clear error and is left as it was.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include <nlohmann/json.hpp>

#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/training/body_anchor_fit.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/truth_simulation.hpp"

namespace {

namespace fs = std::filesystem;

struct BodyProxyOptions {
  std::string model, out;
  float maxDistanceMm = 1000.f * swish::bake::BodyAnchorFitSettings{}.maxDistance;
  float marginMm = 1000.f * swish::bake::BodyAnchorFitSettings{}.margin;
  bool remove = false, oneAnchor = false, secondAtMargin = false, uncalibrated = false, noCover = false,
       bodyJoints = false;
  std::vector<std::string> clips;
  size_t poses = 48;
  float toleranceMm = 1000.f * swish::bake::BodyAnchorCalibrationSettings{}.tolerance;
};

// Every file the --clips arguments name: files as given, folders' .bvh/.fbx/.gltf/.glb files sorted.
std::vector<fs::path> clipFiles(const std::vector<std::string>& args) {
  std::vector<fs::path> out;
  for (const std::string& a : args) {
    if (!fs::is_directory(a)) {
      out.emplace_back(a);
      continue;
    }
    std::vector<fs::path> in;
    for (const auto& e : fs::directory_iterator(a)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
      if (e.is_regular_file() && (ext == ".bvh" || ext == ".fbx" || ext == ".gltf" || ext == ".glb"))
        in.push_back(e.path());
    }
    std::sort(in.begin(), in.end());
    out.insert(out.end(), in.begin(), in.end());
  }
  return out;
}

// `--poses` frames spread evenly over the --clips, with their source simulation (the failed ones left out, as the bake
// leaves them out).
struct SimulatedFrames {
  std::vector<swish::Pose> poses;
  std::vector<std::vector<swish::Mat4f>> skinMatrices;  // each pose's
  std::vector<swish::bake::PoseShape> shapes;           // each ok
};

SimulatedFrames simulateClipFrames(const swish::replay::ModelEntry& entry, const BodyProxyOptions& o) {
  using namespace swish;
  std::vector<Pose> frames;
  for (const fs::path& c : clipFiles(o.clips)) {
    const AnimationClip clip = io::importAnimation(c, entry.model.skeleton);
    frames.insert(frames.end(), clip.frames.begin(), clip.frames.end());
  }
  if (frames.empty()) throw Error("body-proxy: the --clips hold no frame");
  replay::TruthOptions to;
  to.every = 1;
  to.normalMaps = false;
  const replay::ModelTruth truth(entry, to);
  if (!truth.available()) throw Error(o.model + ": no source simulation to calibrate with: " + truth.note());
  const size_t count = std::min(o.poses, frames.size());
  std::vector<Pose> poses;
  for (size_t i = 0; i < count; ++i) poses.push_back(frames[i * frames.size() / count]);
  std::printf("Simulating %zu frames of %zu clip frames (the source simulation of each, in parallel)...\n",
              poses.size(), frames.size());
  std::vector<bake::PoseShape> shapes(poses.size());
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t(0), poses.size(), [&](size_t i) {
    shapes[i] = truth.simulate(poses[i]);
    std::printf("\r  %zu of %zu simulated", ++done, poses.size());
    std::fflush(stdout);
  });
  std::printf("\n");
  SimulatedFrames out;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!shapes[i].ok) continue;
    out.poses.push_back(poses[i]);
    out.skinMatrices.push_back(entry.model.skeleton.skinningMatrices(poses[i]));
    out.shapes.push_back(std::move(shapes[i]));
  }
  if (out.poses.size() < poses.size())
    std::printf("  %zu simulations failed and are left out (as the bake leaves them out)\n",
                poses.size() - out.poses.size());
  return out;
}

// Calibrates `anchors` on those frames: the model's garment there against their simulation.
swish::bake::BodyAnchorCalibration calibrate(const swish::replay::ModelEntry& entry, swish::BodyAnchors& anchors,
                                             const SimulatedFrames& sim, const BodyProxyOptions& o) {
  using namespace swish;
  std::vector<Points3f> predicted(sim.poses.size());
  std::vector<bake::BodyAnchorCalibrationPose> cal;
  for (size_t i = 0; i < sim.poses.size(); ++i) {
    predicted[i] = bake::predictPositions(entry.model, sim.poses[i], false);
    cal.push_back({sim.skinMatrices[i], &sim.shapes[i].gameMeshWorld, &predicted[i]});
  }
  bake::BodyAnchorCalibrationSettings cs;
  cs.tolerance = o.toleranceMm / 1000.f;
  cs.second = !o.secondAtMargin;
  return bake::calibrateBodyAnchors(anchors, cal, cs);
}

// The metadata with `key` set to `value` (null: removed), and the capsule proxy's old entry dropped.
std::string withMetadata(const std::string& metadata, const char* key, const nlohmann::json& value) {
  nlohmann::json meta = nlohmann::json::parse(metadata, nullptr, false);
  if (!meta.is_object()) meta = nlohmann::json::object();
  meta.erase("body_proxy");
  if (value.is_null())
    meta.erase(key);
  else
    meta[key] = value;
  return meta.dump();
}

int runBodyProxy(const BodyProxyOptions& o) {
  using namespace swish;
  if (o.remove) {
    replay::ModelEntry entry = replay::loadModelEntry(o.model);
    entry.model.bodyAnchors = {};
    entry.model.metadata = withMetadata(entry.model.metadata, "body_anchors", nullptr);
    const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);
    saveModel(entry.model, out);
    std::printf("Wrote %s without body anchors (no push-out at run time).\n", out.string().c_str());
    return 0;
  }
  replay::ModelWithBakeBody loaded = replay::loadModelWithBakeBody(o.model, "to anchor the garment to");
  replay::ModelEntry& entry = loaded.entry;
  const Character* character = loaded.character.get();
  const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);
  bake::BodyAnchorFitSettings s;
  s.maxDistance = o.maxDistanceMm / 1000.f;
  s.margin = o.marginMm / 1000.f;
  s.secondAnchors = !o.oneAnchor;
  s.coverAnchors = !o.noCover;
  s.garmentJoints = !o.bodyJoints;
  // The clips' simulated frames also show where the cloth slides over the body (the slide anchors); without
  // --clips there are none.
  SimulatedFrames sim;
  if (!o.clips.empty()) sim = simulateClipFrames(entry, o);
  std::vector<bake::BodyAnchorSlidePose> slidePoses;
  for (size_t i = 0; i < sim.poses.size(); ++i)
    slidePoses.push_back({sim.skinMatrices[i], &sim.shapes[i].gameMeshWorld});
  const bake::BodyAnchorFit fit =
      bake::fitBodyAnchors(character->body, entry.model.skeleton, entry.model.gameMesh, s, slidePoses);
  if (fit.anchored == 0)
    throw Error(o.model + ": no garment vertex lies within " + std::to_string(o.maxDistanceMm) +
                " mm of the body of '" + character->name + "' (nothing written)");
  std::printf(
      "Body of '%s' (%s): %zu of %zu garment vertices anchored (%zu farther than %.0f mm get none).\n"
      "  distance to the anchor at rest: median %.1f mm, p95 %.1f mm, max %.1f mm; ball radius: 10th percentile "
      "%.1f mm, median %.1f mm; %zu inside the body at rest, %zu within the %.1f mm margin of their ball (the "
      "push-out moves them at rest); %zu normals turned outward; %zu with a second anchor%s, %zu of them where the "
      "cloth slides to on its own part (%zu poses%s).\n",
      character->name.c_str(), loaded.how.c_str(), fit.anchored, entry.model.gameMesh.vertexCount(), fit.tooFar,
      fit.maxDistanceMm, fit.medianMm, fit.p95Mm, fit.maxMm, fit.radiusP10Mm, fit.radiusMedianMm, fit.insideAtRest,
      fit.withinMargin, o.marginMm, fit.flippedNormals, fit.secondAnchored, o.oneAnchor ? " (--one-anchor)" : "",
      fit.slideAnchored, fit.slidePoses, o.clips.empty() ? ": they need --clips" : "");
  if (!fit.anchors.third.empty())
    std::printf(
        "  %zu with a third (cover) anchor: of the %zu (pose, vertex) pairs whose skin the first two sets miss by "
        "%.0f mm or more, it covers %zu (%.1f %%).\n",
        fit.coverAnchored, fit.coverMisses, 1000.0 * double(s.slideMinGap), fit.coverCovered,
        fit.coverMisses ? 100.0 * double(fit.coverCovered) / double(fit.coverMisses) : 0.0);
  if (s.garmentJoints)
    std::printf(
        "  anchors on the garment vertex's own joints: %zu anchors changed, %zu influences dropped (weight %.3f mean, "
        "%.3f at most), %zu anchors left with none and removed.\n",
        fit.garmentJointsChanged, fit.garmentJointsDropped, double(fit.garmentJointsMeanDropped),
        double(fit.garmentJointsMaxDropped), fit.garmentJointsRemoved);
  BodyAnchors anchors = fit.anchors;
  nlohmann::json j = bake::toJson(fit);
  j["made_by"] = "swish body-proxy (after the bake)";
  if (!o.clips.empty() && !o.uncalibrated) {
    const bake::BodyAnchorCalibration cal = calibrate(entry, anchors, sim, o);
    std::printf(
        "Calibrated on %zu simulated poses: %zu clearances lowered below the margin (median %.1f mm), %zu anchors "
        "dropped (%zu of them second anchors); on those poses the push-out moves %.1f %% of the vertices and takes "
        "the vertex error against the simulation from %.3f to %.3f mm.\n",
        cal.poses, cal.lowered, cal.medianLoweredMm, cal.dropped, cal.secondDropped, 100.0 * cal.pushedShare,
        cal.meanMmWithout, cal.meanMmWith);
    j["calibration"] = bake::toJson(cal);
    nlohmann::json clips = nlohmann::json::array();
    for (const fs::path& c : clipFiles(o.clips)) clips.push_back(c.filename().string());
    j["calibration"]["poses_from"] = "frames of the clips, simulated";
    j["calibration"]["clips"] = clips;
  } else {
    std::printf("Not calibrated (%s): every anchor keeps the %.1f mm margin.\n",
                o.clips.empty() ? "no --clips" : "--uncalibrated", o.marginMm);
  }
  entry.model.bodyAnchors = anchors;
  entry.model.metadata = withMetadata(entry.model.metadata, "body_anchors", j);
  saveModel(entry.model, out);
  std::printf("Wrote %s (format %u.%u).\n", out.string().c_str(), unsigned(kModelFileMajorVersion),
              unsigned(kModelFileMinorVersion));
  return 0;
}

swish::cli::CommandRegistration reg{
    "body-proxy",
    "Anchor a model's garment to the body it was baked on (the run-time push-out), and write the model with it",
    [](CLI::App& app) -> swish::cli::RunFn {
      auto o = std::make_shared<BodyProxyOptions>();
      app.add_option("model", o->model, "the .swish model (its bake metadata names the character)")->required();
      app.add_option("--out", o->out, "write here instead of over MODEL (written atomically either way)");
      app.add_option("--max-distance-mm", o->maxDistanceMm,
                     "garment vertices farther than this from the rest body get no anchor (default 40)")
          ->check(CLI::Range(1.f, 500.f));
      app.add_option("--margin-mm", o->marginMm,
                     "clearance the push-out keeps between the garment and the anchor's ball (default 2)")
          ->check(CLI::Range(0.f, 1000.f * swish::kMaxAnchorMargin));
      app.add_option("--clips", o->clips,
                     "calibrate on the source simulation of frames of these clips, and take from it where the cloth "
                     "slides over the body (the slide anchors: without --clips there are none) (files or folders of "
                     "BVH/FBX/glTF on the model's skeleton; ideally motion like the model's training clips)");
      app.add_option(
             "--poses", o->poses,
             "frames simulated for the calibration and the slide and cover anchors, spread over the clips "
             "(default 48, about 2.5 s of CPU each; more frames cover more of the motion: the committed default "
             "model's anchors were fitted on 400)")
          ->check(CLI::Range(size_t(1), size_t(100000)));
      app.add_option("--tolerance-mm", o->toleranceMm,
                     "with --clips: mean distance to the simulation per pose that pushing a vertex may add (default "
                     "0: none)")
          ->check(CLI::Range(0.f, 100.f));
      app.add_flag("--uncalibrated", o->uncalibrated,
                   "with --clips: find the slide anchors only; every anchor keeps the margin (as the committed "
                   "default model's: train.anchor_calibration \"none\")");
      app.add_flag("--second-at-margin", o->secondAtMargin,
                   "with --clips: calibrate the first anchors only; the second ones keep the margin");
      app.add_flag("--no-cover-anchors", o->noCover,
                   "with --clips: no third anchor set (format 1.4's push-out: the first set and the second, on another "
                   "part or where the cloth slid farthest)");
      app.add_flag("--body-joints", o->bodyJoints,
                   "keep each anchor's skin as the body's there, also on joints the garment vertex is not skinned to "
                   "(by default those influences are dropped: the run time's push-out then fetches no matrix beyond "
                   "the vertex's skinning's)");
      app.add_flag("--one-anchor", o->oneAnchor,
                   "one anchor per vertex (its nearest body part) instead of also a second one on the nearest other "
                   "part, where two parts meet (format 1.3's push-out)");
      app.add_flag("--remove", o->remove,
                   "write the model without body anchors instead (turns the push-out off for good)");
      app.footer(
          "The push-out: each garment vertex is kept outside the ball of its anchor (the largest ball inside the "
          "rest body touching it at the vertex's closest point, its centre skinned with the body's own weights "
          "there, on the joints the garment vertex is skinned to), `margin` off it; it never pulls a vertex in, and a "
          "vertex answers to its own anchors only: the one "
          "on its nearest body part, then (format 1.4) one on the nearest other part within reach, where parts meet, "
          "or, "
          "for a vertex with no such part, one on its own part where the cloth slid to farthest in the simulated "
          "poses (the jersey rides up over the belly when the arms rise), then (format 1.5) a third, the ball "
          "covering most of the skin the first two still miss in those poses (a bent elbow under its sleeve). "
          "The "
          "bake calibrates "
          "each anchor's clearance on its training poses: the highest at which pushing the network's garment does "
          "not take it further from the simulated one; here --clips does the same with the source simulation of "
          "clip frames. "
          "It runs at the end of "
          "the GPU deform when asked: swish replay --push-out, api::BatchOptions::pushOut. "
          "Models baked with format 1.3 or later carry the anchors already; models of 1.1 and 1.2 carried body "
          "capsules, which are no longer used (this command replaces them).");
      return [o] { return runBodyProxy(*o); };
    }};

}  // namespace
