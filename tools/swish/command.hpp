#pragma once
// Subcommand registration for the swish CLI. Each cmd_*.cpp defines a static CommandRegistration:
//   static swish::cli::CommandRegistration reg{"replay", "Replay recorded frames headlessly", setup};
// where setup(CLI::App& sub) adds options and returns the function run when the subcommand is chosen.
// The run function returns the process exit code; it reports errors itself (swish::Error is caught
// by main and printed as "swish <cmd>: error: ..." with exit code 1).
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace swish::cli {

using RunFn = std::function<int()>;
using SetupFn = std::function<RunFn(CLI::App&)>;

struct CommandInfo {
  std::string name;
  std::string description;
  SetupFn setup;
};

std::vector<CommandInfo>& commandRegistry();

struct CommandRegistration {
  CommandRegistration(std::string name, std::string description, SetupFn setup) {
    commandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace swish::cli
