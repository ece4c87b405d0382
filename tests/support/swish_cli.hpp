#pragma once
// Tests that run the swish program (the targets that include this define SWISH_CLI, its path: see
// tests/CMakeLists.txt), and read back what it wrote.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/paths.hpp"
#include "swish/cluster/process.hpp"

namespace swish::test {

// `swish ARGS...`, waited for: exit code and both outputs.
inline cluster::CommandResult swishCmd(std::vector<std::string> args) {
  args.insert(args.begin(), SWISH_CLI);
  return cluster::runCommand(args);
}

// A file's bytes ("" when it cannot be read).
inline std::string readText(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The committed default model (assets/default/default.swish).
inline std::filesystem::path committedDefaultModel() { return sourceDir() / "assets/default/default.swish"; }

}  // namespace swish::test
