// magbrush-dem — the OpenMP discrete-element engine (run through `magbrush dem`).
//
//   magbrush-dem CASE [--set key=value ...] [--restart FILE] [--threads N] [--output DIR]
#include "dem/dem_run.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/openmp_waiting.h"

#include "coupling/case_parser.h"

#include <cstdlib>
#include <unistd.h>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {
const char *usage =
    R"(Usage: magbrush-dem CASE [--set key=value ...] [--restart FILE] [--threads N] [--output DIR]

Runs the particles of a case (DEM): inserts the populations, lets them settle, and runs to
dem.duration, writing <output.directory>/dem/{particles.xdmf (ParaView), snapshots/*.h5,
time_series.csv, checkpoint.bin}.
  --set key=value  override a case value (as in every magbrush command)
  --restart FILE   continue from a checkpoint (bit-identical to an uninterrupted run)
  --threads N      OpenMP threads (default: dem.threads, then all cores)
  --output DIR     output directory instead of <output.directory>/dem
)";
} // namespace

int main(int argc, char **argv)
{
  // The OpenMP runtime reads its wait policy once, at start-up: choose it (a spin as long
  // as a wake-up, then sleep; openmp_waiting.h) and restart once so that it takes effect.
  if (magbrush::dem::choose_openmp_waiting())
    execv("/proc/self/exe", argv);
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string case_path;
  std::vector<std::string> overrides;
  magbrush::dem::RunOptions options;
  for (std::size_t i = 0; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    auto value = [&](const char *what) -> std::string {
      if (i + 1 >= args.size())
      {
        std::cerr << "magbrush-dem: " << a << " expects " << what << "\n" << usage;
        std::exit(2);
      }
      return args[++i];
    };
    if (a == "--help" || a == "-h")
    {
      std::cout << usage;
      return 0;
    }
    else if (a == "--set")
      overrides.push_back(value("key=value"));
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (a == "--restart")
      options.restart_file = value("a checkpoint file");
    else if (a == "--output")
      options.output_dir = value("a directory");
    else if (a == "--threads")
    {
      const std::string n = value("a thread count");
      char *end = nullptr;
      const long t = std::strtol(n.c_str(), &end, 10);
      if (end == n.c_str() || *end || t < 1 || t > 1024)
      {
        std::cerr << "magbrush-dem: --threads expects a positive count, found '" << n << "'\n";
        return 2;
      }
      options.threads = static_cast<int>(t);
    }
    else if (a == "-np" || a == "--np")
      ++i; // a field-solver option passed along by `magbrush run`: not ours
    else if (a == "--force" || a == "--no-vtu")
      ; // field-solver options passed along by `magbrush run`
    else if (!a.empty() && a[0] == '-')
    {
      std::cerr << "magbrush-dem: unknown option '" << a << "'\n" << usage;
      return 2;
    }
    else if (case_path.empty())
      case_path = a;
    else
    {
      std::cerr << "magbrush-dem: expected one case file, found a second: '" << a << "'\n" << usage;
      return 2;
    }
  }
  if (case_path.empty())
  {
    std::cerr << usage;
    return 2;
  }
  try
  {
    const magbrush::Case c = magbrush::load_case(case_path, overrides);
    magbrush::dem::DemRun run(c, options, std::cout);
    magbrush::dem::add_case_measurements(run, c);
    run.run();
  }
  catch (const magbrush::dem::StabilityError &)
  {
    return 3; // already reported with step, particle, cause and fix
  }
  catch (const std::exception &e)
  {
    std::cerr << "magbrush-dem: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
