// `magbrush dem CASE [--set key=value ...] [--restart FILE] [--threads N] [--output DIR]`:
// runs the OpenMP particle engine bin/magbrush-dem on a case. The driver never links the
// engine; it starts the sibling executable and passes the arguments through.
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

const char *dem_help =
    R"(Usage: magbrush dem CASE [--set key=value ...] [--restart FILE] [--threads N] [--output DIR]

Runs the particles of a case with the discrete-element engine (bin/magbrush-dem): inserts
the populations, lets them settle (dem.settle_time), then runs to dem.duration. Outputs in
<output.directory>/dem/: particles.xdmf (open in ParaView), snapshots/*.h5, time_series.csv
(energies, contacts, wall forces and torques), checkpoint.bin.
  --restart FILE  continue from a checkpoint, bit-identically to an uninterrupted run
  --threads N     OpenMP threads (default: dem.threads, then all cores); results do not
                  depend on it
  --output DIR    write the outputs here instead
A run that becomes unstable (NaN, overlap beyond dem.max_overlap_fraction, kinetic-energy
runaway) stops with exit code 3 and a message naming the step, the particle, the cause and
the likely fix; the last good checkpoint is kept.
)";

int run_dem(const std::vector<std::string> &args)
{
  for (std::size_t i = 1; i < args.size(); ++i)
    if (args[i] == "--help" || args[i] == "-h")
    {
      std::cout << dem_help;
      return 0;
    }
  if (args.size() < 2)
  {
    std::cerr << dem_help;
    return 2;
  }
  const std::string exe = executable_dir() + "/magbrush-dem";
  if (access(exe.c_str(), X_OK) != 0)
  {
    std::cerr << "magbrush dem: the engine '" << exe
              << "' is missing: build it (tools/setup, or cmake --build <build> --target magbrush-dem)\n";
    return 1;
  }
  std::vector<std::string> command = {exe};
  command.insert(command.end(), args.begin() + 1, args.end());
  std::vector<char *> argv;
  for (auto &a : command)
    argv.push_back(const_cast<char *>(a.c_str()));
  argv.push_back(nullptr);
  // How idle threads wait (a short spin, then sleep) is chosen by the engine itself
  // (dem/openmp_waiting.h); a user's own OMP_WAIT_POLICY / GOMP_SPINCOUNT wins.
  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0)
    throw std::runtime_error(std::string("cannot start the DEM engine: ") + std::strerror(errno));
  if (pid == 0)
  {
    execv(exe.c_str(), argv.data());
    std::cerr << "magbrush dem: cannot run '" << exe << "': " << std::strerror(errno) << "\n";
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      throw std::runtime_error(std::string("waiting for the DEM engine: ") + std::strerror(errno));
  if (WIFEXITED(status))
    return WEXITSTATUS(status);
  std::cerr << "magbrush dem: the engine was killed by signal " << WTERMSIG(status) << "\n";
  return 1;
}

const bool registered =
    register_subcommand({"dem", "run the particles (discrete elements) on the stored fields", run_dem, 40});

} // namespace
} // namespace magbrush
