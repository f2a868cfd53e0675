// `magbrush field CASE [--set key=value ...] [-np N] [--only magnetic|electric] [--force]`:
// runs the deal.II field solver bin/magbrush-field (under `mpirun -np N` when N > 1). The
// driver itself never links deal.II; the solver is a sibling executable.
#include "subcommand.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace magbrush {
namespace {

const char *field_help =
  R"(Usage: magbrush field CASE [--set key=value ...] [-np N] [--only magnetic|electric]
                      [--force] [--no-vtu]

Solves the magnetic field of the roller (and the nip's electric field) of a case with the
finite-element solver and stores them as grids in field.output_dir, with the sleeve flux
profile as CSV and ParaView (VTU) files. A stored field whose case hash still matches is
reused ("up to date"); only the field whose inputs changed is recomputed. --force recomputes.
  -np N   run the solver on N MPI processes (mpirun -np N magbrush-field ...)
)";

int run_and_wait(const std::vector<std::string> &command)
{
  std::vector<char *> argv;
  for (const auto &a : command)
    argv.push_back(const_cast<char *>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0)
    throw std::runtime_error(std::string("cannot start the field solver: ") + std::strerror(errno));
  if (pid == 0)
  {
    execvp(argv[0], argv.data());
    std::cerr << "magbrush field: cannot run '" << command[0] << "': " << std::strerror(errno)
              << (command[0] == "mpirun" ? " (is OpenMPI installed? tools/setup installs it)"
                                          : "")
              << "\n";
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      throw std::runtime_error(std::string("waiting for the field solver: ") +
                               std::strerror(errno));
  if (WIFEXITED(status))
    return WEXITSTATUS(status);
  std::cerr << "magbrush field: the field solver was killed by signal " << WTERMSIG(status)
            << "\n";
  return 1;
}

int run_field(const std::vector<std::string> &args)
{
  int n_processes = 1;
  std::vector<std::string> solver_args;
  for (std::size_t i = 1; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    if (a == "--help" || a == "-h")
    {
      std::cout << field_help;
      return 0;
    }
    if ((a == "-np" || a == "--np") && i + 1 < args.size())
    {
      const std::string n = args[++i];
      char *end = nullptr;
      const long value = std::strtol(n.c_str(), &end, 10);
      if (end == n.c_str() || *end != '\0' || value < 1 || value > 4096)
      {
        std::cerr << "magbrush field: -np expects a process count (1, 2, ...), found '" << n
                  << "'\n";
        return 2;
      }
      n_processes = static_cast<int>(value);
      continue;
    }
    solver_args.push_back(a);
  }
  if (solver_args.empty())
  {
    std::cerr << field_help;
    return 2;
  }

  const std::string solver = executable_dir() + "/magbrush-field";
  if (access(solver.c_str(), X_OK) != 0)
  {
    std::cerr << "magbrush field: the field solver '" << solver
              << "' is not there; build it (cmake --build <build dir> --target magbrush-field, "
                 "or tools/setup)\n";
    return 1;
  }
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
  command.insert(command.end(), solver_args.begin(), solver_args.end());
  return run_and_wait(command);
}

const bool registered = register_subcommand(
  {"field", "solve the magnetic (and electric) fields and store them as grids", run_field, 30});

} // namespace
} // namespace magbrush
