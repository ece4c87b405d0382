#pragma once
// Running the scheduler's commands (sbatch, squeue): argv as given, no shell, stdout and stderr kept.
#include <string>
#include <vector>

namespace swish::cluster {

struct CommandResult {
  int exitCode = -1;  // the program's exit status; 127: it could not be started (not installed)
  std::string out, err;
};

// Runs argv[0] (looked up in PATH) with argv, waits for it. Never throws for a failing program.
CommandResult runCommand(const std::vector<std::string>& argv);

// "sbatch --parsable --array=0-3 'a b.sh'": argv as one line a person can paste into a shell.
std::string shellLine(const std::vector<std::string>& argv);
// One word quoted for bash: 'it'\''s'.
std::string shellQuote(const std::string& word);

}  // namespace swish::cluster
