// magbrush-dem — the OpenMP discrete-element engine (run through `magbrush dem`).
//
//   magbrush-dem CASE [--set key=value ...] [--restart FILE | --resume] [--threads N] [--output DIR]
#include "dem/dem_command_line.h"
#include "dem/dem_run.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/huge_page_heap.h"
#include "dem/openmp_waiting.h"

#include "case/case_parser.h"

#include <cstdlib>
#include <unistd.h>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {
// The engine's options, declared once for it and for `magbrush dem` (dem_command_line.h).
const magbrush::cli::CommandSpec &command_line()
{
  static const magbrush::cli::CommandSpec spec = magbrush::dem::engine_command_line("magbrush-dem");
  return spec;
}

int run_engine(const magbrush::cli::ParsedArguments &args)
{
  magbrush::dem::RunOptions options;
  options.restart_file = args.value("--restart");
  options.restart_anyway = args.has("--restart-anyway");
  options.resume = args.has("--resume");
  if (options.resume && !options.restart_file.empty())
    throw magbrush::cli::UsageError("--resume continues from the output folder's own checkpoint; --restart names "
                                    "another one: give one of them");
  options.output_dir = args.value("--output");
  if (args.has("--threads"))
    options.threads = static_cast<int>(args.whole_number("--threads", 0, 1, 1024));
  try
  {
    const magbrush::Case c = magbrush::load_case(args.positional(0), args.values("--set"));
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
} // namespace

int main(int argc, char **argv)
{
  // The OpenMP runtime reads its wait policy once, at start-up, and glibc its allocator
  // tunables: choose them (a spin as long as a wake-up, then sleep: openmp_waiting.h; the
  // arrays on huge pages: huge_page_heap.h) and restart once so that they take effect.
  const bool waiting = magbrush::dem::choose_openmp_waiting();
  const bool huge_pages = magbrush::dem::choose_huge_page_heap();
  if (waiting || huge_pages)
    execv("/proc/self/exe", argv);
  return magbrush::cli::run_command(command_line(), {argv + 1, argv + argc}, run_engine);
}
