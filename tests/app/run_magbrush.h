// The built `magbrush` driver run as a user runs it, for the tests of its subcommands: its exit
// status and everything it printed (stdout and stderr together, kept in <dir>/log.txt).
#pragma once

#include "common/child_process.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace magbrush::testing {

struct CliRun
{
  int status;
  std::string output;
};

inline CliRun run_magbrush(const std::filesystem::path &dir, const std::vector<std::string> &args)
{
  std::vector<std::string> command = {std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush"};
  command.insert(command.end(), args.begin(), args.end());
  magbrush::ChildOutput output;
  output.stdout_path = (dir / "log.txt").string();
  output.stderr_to_stdout = true;
  CliRun r{magbrush::run_program(command, output), {}};
  std::ifstream in(dir / "log.txt");
  std::ostringstream text;
  text << in.rdbuf();
  r.output = text.str();
  return r;
}

} // namespace magbrush::testing
