#pragma once
// The command-line options that change the bake's source simulation when a command rebuilds it as ground
// truth (replay::ModelTruth): `swish replay --truth-every N` and `swish levels`. One definition, so that the
// two commands take the same overrides with the same names, ranges and help, bound straight to
// replay::TruthOptions (`every` and `normalMaps` stay the caller's).
#include <CLI/CLI.hpp>
#include <string>

#include "swish/replay/truth_simulation.hpp"

namespace swish::cli {

// `saidWhere`: where the run says what was overridden ("the report", "the ladder's 'measured_on'").
void addTruthOverrideOptions(CLI::App& app, replay::TruthOptions& truth, const std::string& saidWhere);

}  // namespace swish::cli
