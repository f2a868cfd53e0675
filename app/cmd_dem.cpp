// `magbrush dem CASE [--set key=value ...] [--restart FILE | --resume] [--threads N] [--output DIR]`:
// runs the OpenMP particle engine bin/magbrush-dem on a case. The driver never links the
// engine; it checks the arguments against the engine's own declaration
// (dem/dem_command_line.h) and starts the sibling executable with them.
#include "app/subcommand.h"

#include "common/child_process.h"
#include "dem/dem_command_line.h"

#include <iostream>
#include <string>
#include <unistd.h>
#include <vector>

namespace magbrush {
namespace {

const cli::CommandSpec &dem_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s = dem::engine_command_line("magbrush dem");
    s.examples = {{"magbrush dem cases/kawamoto_nip_fed.yaml --threads 2",
                   "the particles on the stored fields (run `magbrush field` first)"},
                  {"magbrush dem cases/kawamoto_nip_fed.yaml --resume",
                   "continue a stopped run from its checkpoint"}};
    s.exit_status = "0 done, 1 invalid case or missing fields, 2 bad usage, 3 an unstable run stopped.";
    return s;
  }();
  return spec;
}

int dem_stage(const cli::ParsedArguments &args)
{
  const std::string exe = executable_dir() + "/magbrush-dem";
  if (access(exe.c_str(), X_OK) != 0)
  {
    std::cerr << "magbrush dem: the engine '" << exe
              << "' is missing: build it (tools/setup, or cmake --build <build> --target magbrush-dem)\n";
    return 1;
  }
  std::vector<std::string> command = {exe, args.positional(0)};
  const auto options = cli::forward_options(args, dem_command_line(), cli::Forward::every_option);
  command.insert(command.end(), options.begin(), options.end());
  // How idle threads wait (a short spin, then sleep) is chosen by the engine itself
  // (dem/openmp_waiting.h); a user's own OMP_WAIT_POLICY / GOMP_SPINCOUNT wins.
  return run_program(command);
}

int run_dem(const std::vector<std::string> &args)
{
  return cli::run_command(dem_command_line(), {args.begin() + 1, args.end()}, dem_stage);
}

const bool registered = register_subcommand(
    {"dem", "run the particles (discrete elements) on the stored fields", run_dem, dem_command_line, 40});

} // namespace
} // namespace magbrush
