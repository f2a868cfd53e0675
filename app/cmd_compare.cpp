// `magbrush compare RUN_A RUN_B [...]`: finished runs side by side on one page — each run's
// key numbers with standard errors, the differences from the first run and whether they are
// beyond the combined error, the inputs that differ, the nip, flux and development profiles
// overlaid. A run is a run folder, as `magbrush run` names it (results/<case>[-<digest>]).
//
// The steps: check that every folder holds a finished run (dem/summary.csv), then call
// tools/compare.py (found like the report's script) with the interpreter the report uses; it
// writes index.html, index.md, compare.csv and the PNGs.
#include "app/subcommand.h"

#include "common/child_process.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

const cli::CommandSpec &compare_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush compare";
    s.usage = "magbrush compare RUN_A RUN_B [RUN ...] [-o DIR]";
    s.description = R"(Puts finished runs side by side. A run is the folder `magbrush run` wrote (results/<case>, or
results/<case>-<digest> for a run with --set overrides); the first is the reference. Writes
into DIR (default: results/compare_<A>_vs_<B>, the folders' names):
  index.html, index.md   every key number of each run's dem/summary.csv as value ± standard
                         error, the difference of each run from the first and whether it is
                         beyond the combined error (|b - a| > 2 sqrt(se_a^2 + se_b^2)); the
                         inputs that differ (from each run's case_resolved.txt); each pole's
                         sleeve-flux peak in the first run and how far it moved in the
                         others (angle, Bn): a pole moved or made stronger; the plots
  compare.csv            the same numbers, one row per key and run
  compare_nip_slip.png, compare_nip_pressure.png, compare_nip_density.png   the nip profiles
  compare_flux.png       the sleeve's normal flux of each run's stored field
  compare_developed_profile.png   the developed toner across an image period
  (each plot only when the runs have that profile)
)";
    s.positionals = {{"RUN_A", "the reference run folder"},
                     {"RUN_B", "the run folders to compare with it", cli::Positional::one_or_more}};
    s.options = {{"--output", {"-o"}, "DIR", "write the page here", false, {}, /*for_pipeline=*/false}};
    s.epilog = R"(Needs python3 (numbers and tables); the plots also matplotlib. $MAGBRUSH_PYTHON picks the
interpreter, $MAGBRUSH_TOOLS the folder holding compare.py.
)";
    s.examples = {{"magbrush compare results/kawamoto_nip_fed-171ed7 results/kawamoto_nip_fed-a1c7b3 -o results/compare_gap",
                   "the quick run against its 0.5 mm gap variant (`magbrush run` prints each run's folder)"}};
    s.exit_status = "0 written, 1 a folder without a finished run or a failed script, 2 bad usage.";
    return s;
  }();
  return spec;
}

std::string python_interpreter()
{
  if (const char *env = std::getenv("MAGBRUSH_PYTHON"))
    return env;
  if (fs::exists("/usr/bin/python3"))
    return "/usr/bin/python3";
  return "python3";
}

// "results/a-1c2d3e/" -> "a-1c2d3e"
std::string folder_name(const std::string &run)
{
  const fs::path p = fs::path(run).lexically_normal();
  return p.filename().empty() ? p.parent_path().filename().string() : p.filename().string();
}

int compare(const cli::ParsedArguments &args)
{
  const std::vector<std::string> runs = args.positionals();
  if (runs.size() < 2)
    throw cli::UsageError("give at least two run folders (e.g. results/<case> results/<case>-<digest>)");
  for (const auto &run : runs)
  {
    if (fs::is_regular_file(run))
    {
      std::cerr << "magbrush compare: " << run << " is a file; give the run folders `magbrush run` wrote (its "
                << "last lines name them: results/<case>[-<digest>])\n";
      return 1;
    }
    if (!fs::exists(fs::path(run) / "dem" / "summary.csv"))
    {
      std::cerr << "magbrush compare: " << run << " holds no finished run: " << (fs::path(run) / "dem" / "summary.csv").string()
                << " is missing (run it first: magbrush run CASE [--set ...]; its folder is printed at the start)\n";
      return 1;
    }
  }
  std::string out = args.value("--output");
  if (out.empty())
    out = (fs::path("results") / ("compare_" + folder_name(runs[0]) + "_vs_" + folder_name(runs[1]) +
                                  (runs.size() > 2 ? "_and_" + std::to_string(runs.size() - 2) + "_more" : "")))
              .string();
  const std::string script = find_tool_script("compare.py");
  if (script.empty())
  {
    std::cerr << "magbrush compare: tools/compare.py not found next to the sources of this build; set MAGBRUSH_TOOLS "
                 "to the folder that holds it\n";
    return 1;
  }
  std::vector<std::string> command = {python_interpreter(), script, "--out", out};
  command.insert(command.end(), runs.begin(), runs.end());
  if (const std::string why = run_program_failure(command); !why.empty())
  {
    std::cerr << "magbrush compare: tools/compare.py failed (" << why << ")\n";
    return 1;
  }
  std::cout << "magbrush compare: " << (fs::path(out) / "index.html").string() << " (and index.md, compare.csv)\n";
  return 0;
}

int run_compare(const std::vector<std::string> &args)
{
  return cli::run_command(compare_command_line(), {args.begin() + 1, args.end()}, compare);
}

const bool registered = register_subcommand(
    {"compare", "finished runs side by side: key numbers with errors, differing inputs, overlaid profiles",
     run_compare, compare_command_line, 60});

} // namespace
} // namespace magbrush
