// swish body-proxy MODEL [--out OUT]: fits the body anchors of the run-time push-out
// (bake/training/body_anchor_fit.hpp: per garment vertex, the closest point of the rest body, its
// outward normal and its skin) to the body the model was baked on, and writes the model with them
// (format 1.3). `swish bake` fits them itself; this is for a model baked before they existed: nothing
// else in the model changes, and the network is not retrained. `--remove` writes the model without
// them (no push-out at run time).
//
// The body is rebuilt as `swish replay --truth-every` rebuilds it, from the model's own bake metadata
// (the embedded default character by code, or the recipe/character file it names, looked for as
// written and beside the model), and checked to match the model's skeleton, game mesh and skin. A
// model whose bake character cannot be rebuilt gets a clear error and is left as it was.
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "swish/bake/training/body_anchor_fit.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/truth_simulation.hpp"

namespace {

namespace fs = std::filesystem;

struct BodyProxyOptions {
  std::string model, out;
  float maxDistanceMm = 1000.f * swish::bake::BodyAnchorFitSettings{}.maxDistance;
  float marginMm = 1000.f * swish::bake::BodyAnchorFitSettings{}.margin;
  bool remove = false;
};

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
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(character->body, entry.model.skeleton, entry.model.gameMesh, s);
  if (fit.anchored == 0)
    throw Error(o.model + ": no garment vertex lies within " + std::to_string(o.maxDistanceMm) +
                " mm of the body of '" + character->name + "' (nothing written)");
  std::printf(
      "Body of '%s' (%s): %zu of %zu garment vertices anchored (%zu farther than %.0f mm get none).\n"
      "  distance to the anchor at rest: median %.1f mm, p95 %.1f mm, max %.1f mm; ball radius: 10th percentile "
      "%.1f mm, median %.1f mm; %zu inside the body at rest, %zu within the %.1f mm margin of their ball (the "
      "push-out moves them at rest); %zu normals turned outward.\n",
      character->name.c_str(), loaded.how.c_str(), fit.anchored, entry.model.gameMesh.vertexCount(), fit.tooFar,
      fit.maxDistanceMm, fit.medianMm, fit.p95Mm, fit.maxMm, fit.radiusP10Mm, fit.radiusMedianMm, fit.insideAtRest,
      fit.withinMargin, o.marginMm, fit.flippedNormals);
  BodyAnchors anchors = fit.anchors;
  nlohmann::json j = bake::toJson(fit);
  j["made_by"] = "swish body-proxy (after the bake)";
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
      app.add_flag("--remove", o->remove,
                   "write the model without body anchors instead (turns the push-out off for good)");
      app.footer(
          "The push-out: each garment vertex is kept outside the ball of its anchor (the largest ball inside the "
          "rest body touching it at the vertex's closest point, its centre skinned with the body's own weights "
          "there), `margin` off it; it never pulls a vertex in, and a vertex answers to its own anchor only. It "
          "runs at the end of "
          "the GPU deform when asked: swish replay --push-out, api::BatchOptions::pushOut. "
          "Models baked with format 1.3 or later carry the anchors already; models of 1.1 and 1.2 carried body "
          "capsules, which are no longer used (this command replaces them).");
      return [o] { return runBodyProxy(*o); };
    }};

}  // namespace
