// swish body-coverage MODEL --clips A.bvh [B.bvh ...]: lists the body triangles the garment covers
// (bake/transfer/body_coverage.hpp) for a model baked before format 1.2, without re-baking, and
// writes the model with the list. `swish bake` makes the list itself from the simulated training
// shapes; here the garment of each pose is the MODEL's own reconstruction (network, guard, PCA,
// skinning) over frames of the clips given, which should be the clips the model was baked from: a
// stand-in for the simulated shapes, within the model's error of them.
//
// The body is rebuilt from the model's bake metadata as `swish body-proxy` and `swish replay
// --truth-every` rebuild it.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/transfer/body_coverage.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/truth_simulation.hpp"

namespace {

namespace fs = std::filesystem;

struct BodyCoverageCliOptions {
  std::string model, out;
  std::vector<std::string> clips;
  size_t poses = 400;
  double share = swish::bake::BodyCoverageOptions{}.minShare;
};

int runBodyCoverage(const BodyCoverageCliOptions& o) {
  using namespace swish;
  replay::ModelWithBakeBody loaded = replay::loadModelWithBakeBody(o.model, "to test coverage against");
  replay::ModelEntry& entry = loaded.entry;
  const Character* character = loaded.character.get();
  const std::string& how = loaded.how;
  const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);

  std::vector<Pose> frames;
  for (const std::string& c : o.clips) {
    io::AnimationImportOptions ao;
    const AnimationClip clip = io::importAnimation(c, entry.model.skeleton, ao);
    frames.insert(frames.end(), clip.frames.begin(), clip.frames.end());
  }
  if (frames.empty()) throw Error("body coverage: the clips hold no frame");
  const size_t step = std::max<size_t>(1, frames.size() / std::max<size_t>(1, o.poses));
  std::vector<bake::DatasetPose> poses;
  for (size_t f = 0; f < frames.size(); f += step) {
    bake::DatasetPose p;
    p.id = uint32_t(poses.size());
    p.pose = frames[f];
    p.gameMeshWorld = bake::predictPositions(entry.model, p.pose, false);
    poses.push_back(std::move(p));
  }
  std::vector<const bake::DatasetPose*> ptrs;
  for (const auto& p : poses) ptrs.push_back(&p);
  bake::BodyCoverageOptions bo;
  bo.minShare = o.share;
  bo.maxPoses = poses.size();
  const bake::BodyCoverageResult r = bake::coveredBodyTriangles(*character, ptrs, bo);
  std::printf("Body of '%s' (%s), %u triangles; %zu poses (every %zu of %zu clip frames), the model's own garment:\n",
              character->name.c_str(), how.c_str(), r.bodyTriangles, r.poses, step, frames.size());
  for (const auto& [share, count] : r.byShare)
    std::printf("  covered in %3.0f %% of the poses: %u triangles\n", 100.0 * share, count);
  entry.model.bodyCoverage = {r.bodyTriangles, r.covered};
  nlohmann::json meta = nlohmann::json::parse(entry.model.metadata);
  nlohmann::json clips = nlohmann::json::array();
  for (const std::string& c : o.clips) clips.push_back(fs::path(c).filename().string());
  meta["body_coverage"] = {{"made_by", "swish body-coverage (after the bake)"},
                           {"garment", "the model's own reconstruction, not the simulation"},
                           {"clips", clips},
                           {"body_triangles", r.bodyTriangles},
                           {"covered", r.covered.size()},
                           {"min_share_of_poses", o.share},
                           {"poses_tested", r.poses},
                           {"covered_by_share_of_poses", r.byShare}};
  entry.model.metadata = meta.dump();
  saveModel(entry.model, out);
  std::printf("Wrote %s with %zu covered triangles (at least %.0f %% of the poses; format %u.%u).\n",
              out.string().c_str(), r.covered.size(), 100.0 * o.share, unsigned(kModelFileMajorVersion),
              unsigned(kModelFileMinorVersion));
  return 0;
}

swish::cli::CommandRegistration reg{
    "body-coverage", "List the body triangles a model's garment covers (for renderers to leave out), without re-baking",
    [](CLI::App& app) -> swish::cli::RunFn {
      auto o = std::make_shared<BodyCoverageCliOptions>();
      app.add_option("model", o->model, "the .swish model (its bake metadata names the character)")->required();
      app.add_option("--clips", o->clips,
                     "animation clips to pose the model with (BVH/glTF/FBX on its skeleton): the clips it was baked "
                     "from")
          ->required();
      app.add_option("--poses", o->poses, "frames taken, evenly spaced over the clips (default 400)")
          ->check(CLI::Range(size_t(1), size_t(100000)));
      app.add_option("--share", o->share, "share of the poses a triangle must be covered in (default 0.98)")
          ->check(CLI::Range(0.01, 1.0));
      app.add_option("--out", o->out, "write here instead of over MODEL (written atomically either way)");
      app.footer(
          "A model baked with format 1.2 or later already carries the list, made from its simulated training "
          "shapes; swish render / swish replay --render leave the triangles out with --hide-covered-body.");
      return [o] { return runBodyCoverage(*o); };
    }};

}  // namespace
