// `magbrush field CASE [--set key=value ...] [-np N] [--only magnetic|electric] [--force]`:
// runs the deal.II field solver bin/magbrush-field (under `mpirun -np N` when N > 1). The
// driver itself never links deal.II; the solver is a sibling executable, and its options are
// declared once, in field_solver/field_command_line.h, for both programs.
#include "app/subcommand.h"

#include "common/child_process.h"
#include "field_solver/field_command_line.h"

#include <cstdlib>
#include <iostream>
#include <string>
#include <unistd.h>
#include <vector>

namespace magbrush {
namespace {

// The solver's options as magbrush-field itself declares them (what is handed on to it).
const cli::CommandSpec &solver_command_line()
{
  static const cli::CommandSpec spec = field::solver_command_line("magbrush-field");
  return spec;
}

// The solver's options plus the number of MPI processes, which only the driver knows about.
const cli::CommandSpec &field_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s = field::solver_command_line("magbrush field");
    s.usage = "magbrush field CASE [--set key=value ...] [-np N] [--only magnetic|electric]\n"
              "                      [--force] [--no-vtu]";
    s.options.push_back({"--np", {"-np"}, "N", "run the solver on N MPI processes (mpirun -np N magbrush-field ...)"});
    s.examples = {{"magbrush field cases/kawamoto_nip_fed.yaml",
                   "solve and store the fields (reused when their inputs are unchanged)"},
                  {"magbrush field cases/kweon_development.yaml -np 2 --only electric",
                   "the electric field on 2 MPI processes"}};
    s.exit_status = "0 solved or up to date, 1 invalid case or solver failure, 2 bad usage.";
    return s;
  }();
  return spec;
}

// mpirun, when asked for more than one process, then the solver with its own arguments.
std::vector<std::string> solver_command(const std::string &solver, const cli::ParsedArguments &args)
{
  const long n_processes = args.whole_number("--np", 1, 1, 4096);
  std::vector<std::string> command;
  if (n_processes > 1)
  {
    // OpenMPI refuses to run as root (containers, CI) unless told that this is intended.
    if (geteuid() == 0)
    {
      setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
      setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
    }
    command = {"mpirun", "--oversubscribe", "-np", std::to_string(n_processes)};
  }
  command.push_back(solver);
  command.push_back(args.positional(0));
  const auto options = cli::forward_options(args, solver_command_line(), cli::Forward::every_option);
  command.insert(command.end(), options.begin(), options.end());
  return command;
}

int field_stage(const cli::ParsedArguments &args)
{
  const std::string solver = executable_dir() + "/magbrush-field";
  const std::vector<std::string> command = solver_command(solver, args);
  if (access(solver.c_str(), X_OK) != 0)
  {
    std::cerr << "magbrush field: the field solver '" << solver
              << "' is not there; build it (cmake --build <build dir> --target magbrush-field, "
                 "or tools/setup)\n";
    return 1;
  }
  if (command[0] == "mpirun" && !program_exists("mpirun"))
  {
    std::cerr << "magbrush field: cannot run 'mpirun': it is not on the PATH (is OpenMPI installed? "
                 "tools/setup installs it)\n";
    return 1;
  }
  return run_program(command);
}

int run_field(const std::vector<std::string> &args)
{
  return cli::run_command(field_command_line(), {args.begin() + 1, args.end()}, field_stage);
}

const bool registered = register_subcommand({"field", "solve the magnetic (and electric) fields and store them as grids",
                                              run_field, field_command_line, 30});

} // namespace
} // namespace magbrush
