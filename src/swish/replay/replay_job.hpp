#pragma once
// A whole `swish replay` run: load the models, run the engine, write the outputs. Everything goes to a
// staging folder beside the output folder ("<out>.partial-<pid>"), renamed over it only when the run
// has finished, so an error leaves no partial outputs (and the previous outputs intact).
#include <filesystem>
#include <string>

#include "swish/replay/model_library.hpp"
#include "swish/replay/replay_engine.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct ReplayJobOptions {
  ReplayOptions engine;
  bool quiet = false;
  ModelLibrary* models = nullptr;  // the scene's models, when the caller already loaded them (else loaded here)
};

struct ReplayJobResult {
  ReplayResult result;
  std::filesystem::path directory;  // where the outputs are (empty if none were asked for)
};

// Throws Error (nothing left behind) when the scene cannot be replayed.
ReplayJobResult runReplayJob(const runtime::Scene& scene, const ReplayJobOptions& options);

}  // namespace swish::replay
