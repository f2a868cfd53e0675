// The `magbrush` driver is a table of subcommands. Each subcommand lives in its own
// cmd_<name>.cpp and registers itself at start-up:
//
//   static const bool registered = magbrush::register_subcommand(
//       {"check", "validate a case and print it with units", run_check, check_command_line, 10});
//
// so adding a subcommand never touches main.cpp. `run` receives the arguments after the
// subcommand name (argv[0] is the subcommand name) and returns the process exit code.
// `command_line` returns the subcommand's declared options (common/command_line.h): it parses
// its arguments with them, and `magbrush run` reads them to hand each stage only its own.
#pragma once

#include "common/command_line.h"

#include <string>
#include <vector>

namespace magbrush {

struct Subcommand
{
  std::string name;
  std::string summary; // one line for `magbrush --help`
  int (*run)(const std::vector<std::string> &args);
  const cli::CommandSpec &(*command_line)();
  int order = 100;     // position in `magbrush --help` (pipeline order)
};

bool register_subcommand(const Subcommand &command);
const std::vector<Subcommand> &subcommands();
// The subcommand called `name`, or nullptr.
const Subcommand *find_subcommand(const std::string &name);

// Directory holding the magbrush executables (to find magbrush-field, magbrush-dem).
std::string executable_dir();

// The plotting script tools/<name> (report.py, plot_sweep.py, plot_flux.py): from
// $MAGBRUSH_TOOLS, the tools/ folder of the source tree this binary was built from, or next to
// the executable (build/bin → ../../tools, an install's share/magbrush/tools); "" if none.
std::string find_tool_script(const std::string &name);

} // namespace magbrush
