// swish body-proxy MODEL [--out OUT]: fits the body proxy of the run-time push-out (capsules on the
// skinning joints, bake/training/body_proxy_fit.hpp) to the body the model was baked on, and writes the model
// with it (format 1.1). `swish bake` fits it itself; this is for a model baked before the proxy existed
// (format 1.0, e.g. a model whose bake took an hour): nothing else in the model changes, and the
// network is not retrained.
//
// The body is rebuilt as `swish replay --truth-every` rebuilds it, from the model's own bake metadata
// (the embedded default character by code, or the recipe/character file it names, looked for as
// written and beside the model), and checked to match the model's skeleton, game mesh and skin. A
// model whose bake character cannot be rebuilt gets a clear error and is left as it was.
#include <cstdio>
#include <filesystem>
#include <string>

#include "swish/bake/training/body_proxy_fit.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/truth_simulation.hpp"

namespace {

namespace fs = std::filesystem;

struct BodyProxyOptions {
  std::string model, out;
  float reach = 0.5f;
  bool remove = false;
};

int runBodyProxy(const BodyProxyOptions& o) {
  using namespace swish;
  if (o.remove) {
    replay::ModelEntry entry = replay::loadModelEntry(o.model);
    entry.model.bodyProxy = {};
    const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);
    saveModel(entry.model, out);
    std::printf("Wrote %s without a body proxy (no push-out at run time).\n", out.string().c_str());
    return 0;
  }
  replay::ModelWithBakeBody loaded = replay::loadModelWithBakeBody(o.model, "to fit the proxy to");
  replay::ModelEntry& entry = loaded.entry;
  const Character* character = loaded.character.get();
  const std::string& how = loaded.how;
  const fs::path out = o.out.empty() ? entry.file : fs::path(o.out);
  bake::BodyProxyFitSettings s;
  s.reach = o.reach;
  const bake::BodyProxyFit fit = bake::fitBodyProxy(character->body, entry.model.skeleton, &entry.model.gameMesh, s);
  if (fit.proxy.empty())
    throw Error(o.model + ": no capsule fits the body of '" + character->name + "' (nothing written)");
  std::printf(
      "Body of '%s' (%s): %zu (joint, part) groups, %zu capsules kept, %zu dropped; the surfaces checked stand at most "
      "%.2f mm outside the body.\n",
      character->name.c_str(), how.c_str(), fit.groups, fit.proxy.capsules.size(), fit.dropped, fit.worstOutsideMm);
  for (size_t c = 0; c < fit.proxy.capsules.size(); ++c) {
    const BodyCapsule& k = fit.proxy.capsules[c];
    std::printf("  %-16s radius %5.1f mm, length %5.1f mm\n", fit.capsuleJoints[c].c_str(), 1000.f * k.radius,
                1000.f * (k.b - k.a).norm());
  }
  entry.model.bodyProxy = fit.proxy;
  saveModel(entry.model, out);
  std::printf("Wrote %s (format %u.%u).\n", out.string().c_str(), unsigned(kModelFileMajorVersion),
              unsigned(kModelFileMinorVersion));
  return 0;
}

swish::cli::CommandRegistration reg{
    "body-proxy",
    "Fit the run-time push-out's body proxy to the body a model was baked on, and write the model with it",
    [](CLI::App& app) -> swish::cli::RunFn {
      auto o = std::make_shared<BodyProxyOptions>();
      app.add_option("model", o->model, "the .swish model (its bake metadata names the character)")->required();
      app.add_option("--out", o->out, "write here instead of over MODEL (written atomically either way)");
      app.add_option("--reach", o->reach,
                     "keep capsules within this many metres of the garment's rest bounds (default 0.5; negative: all)");
      app.add_flag("--remove", o->remove, "write the model without a proxy instead (turns the push-out off for good)");
      return [o] { return runBodyProxy(*o); };
    }};

}  // namespace
