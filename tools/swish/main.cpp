// swish: neural-network cloth for tight garments. Subcommands live in cmd_*.cpp.
#include <algorithm>
#include <cstdio>
#include <exception>

#include "swish/command.hpp"
#include "swish/core/error.hpp"

namespace swish::cli {
std::vector<CommandInfo>& commandRegistry() {
  static std::vector<CommandInfo> r;
  return r;
}
}  // namespace swish::cli

int main(int argc, char** argv) {
  using namespace swish::cli;
  CLI::App app{
      "swish: deforms tight clothing on game characters with a small neural network (after EA's Swish,\n"
      "SIGGRAPH 2021). 'swish bake' turns a character and animation into a .swish model; 'swish replay'\n"
      "replays frames headlessly and reports error against run time.\n"
      "Run 'swish <command> --help' for the options of a command."};
  app.require_subcommand(1);
  auto& reg = commandRegistry();
  std::sort(reg.begin(), reg.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, RunFn>> runs;
  for (auto& c : reg) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    runs.emplace_back(sub, c.setup(*sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, run] : runs) {
    if (!sub->parsed()) continue;
    try {
      return run();
    } catch (const swish::Error& e) {
      std::fprintf(stderr, "swish %s: error: %s\n", sub->get_name().c_str(), e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "swish %s: internal error: %s\n", sub->get_name().c_str(), e.what());
      return 2;
    }
  }
  return 0;
}
