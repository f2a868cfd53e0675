// The `magbrush` driver is a table of subcommands. Each subcommand lives in its own
// cmd_<name>.cpp and registers itself at start-up:
//
//   static const bool registered = magbrush::register_subcommand(
//       {"check", "validate a case and print it with units", run_check});
//
// so adding a subcommand never touches main.cpp. `run` receives the arguments after the
// subcommand name (argv[0] is the subcommand name) and returns the process exit code.
#pragma once

#include <string>
#include <vector>

namespace magbrush {

struct Subcommand
{
  std::string name;
  std::string summary; // one line for `magbrush --help`
  int (*run)(const std::vector<std::string> &args);
  int order = 100;     // position in `magbrush --help` (pipeline order)
};

bool register_subcommand(const Subcommand &command);
const std::vector<Subcommand> &subcommands();

// Directory holding the magbrush executables (to find magbrush-field, magbrush-dem).
std::string executable_dir();

} // namespace magbrush
