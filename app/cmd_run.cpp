// `magbrush run CASE`: the whole pipeline — validate, fields, DEM, report (the Gmsh meshes
// only when --only names them: no later stage reads them) — each stage skipped when its
// outputs are up to date (the stages themselves decide that), with progress and an ETA at
// every stage, the wall time of every stage, and at the end a summary of where every output is.
//
//   --quick: the case's duration and every window scaled (app/quick_preset.h), as overrides
//   check: quietly; then the case in ten lines (app/case_at_a_glance.h), the resolved case and
//   the overrides written into the run folder (case/run_folder.h names it)
//   for each stage: announce it (with the time it took last time: its ETA) → run it; the DEM's
//   output is also kept in <output.directory>/dem/dem.log (the report reads its timing table)
//   → record the stage's wall time in <output.directory>/run_times.csv
//   then: the table of times, and the list of outputs with their paths.
#include "app/case_at_a_glance.h"
#include "app/quick_preset.h"
#include "app/run_pipeline.h"
#include "app/subcommand.h"

#include "case/case_format.h"
#include "case/case_parser.h"
#include "case/run_folder.h"
#include "common/atomic_file.h"
#include "fields/field_files.h"
#include "case/units.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> split_commas(const std::string &s)
{
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size())
  {
    const size_t end = s.find(',', start);
    out.push_back(s.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  return out;
}

bool contains(const std::vector<std::string> &v, const std::string &s)
{
  for (const auto &x : v)
    if (x == s)
      return true;
  return false;
}

// Copies everything this process (and its children) write to stdout/stderr into a log file
// as well, while it lives: fd 1 and 2 go to a pipe that a thread drains into both.
class TeeOutput
{
public:
  // append: keep what the log holds (a resumed run adds its part after the earlier runs').
  TeeOutput(const std::string &log_path, bool append)
      : log_(log_path, append ? std::ios::out | std::ios::app : std::ios::out)
  {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    if (!log_ || pipe(pipe_) != 0)
      return;
    saved_out_ = dup(1);
    dup2(pipe_[1], 1);
    dup2(pipe_[1], 2);
    close(pipe_[1]);
    reader_ = std::thread([this] {
      char buffer[4096];
      ssize_t n;
      while ((n = read(pipe_[0], buffer, sizeof buffer)) > 0)
      {
        ssize_t done = 0;
        while (done < n)
        {
          const ssize_t w = write(saved_out_, buffer + done, static_cast<size_t>(n - done));
          if (w <= 0)
            break;
          done += w;
        }
        log_.write(buffer, n);
        log_.flush();
      }
    });
    active_ = true;
  }
  ~TeeOutput()
  {
    if (!active_)
      return;
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    // Put the terminal back on fd 1 and 2: the pipe's last writer closes and the thread ends.
    const int saved_err = dup(saved_out_);
    dup2(saved_out_, 1);
    dup2(saved_err, 2);
    close(saved_err);
    reader_.join();
    close(pipe_[0]);
    close(saved_out_);
  }
  TeeOutput(const TeeOutput &) = delete;
  TeeOutput &operator=(const TeeOutput &) = delete;

private:
  std::ofstream log_;
  int pipe_[2] = {-1, -1};
  int saved_out_ = -1;
  std::thread reader_;
  bool active_ = false;
};

std::map<std::string, double> read_run_times(const fs::path &path)
{
  std::map<std::string, double> times;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line))
  {
    const auto comma = line.find(',');
    if (comma != std::string::npos)
      times[line.substr(0, comma)] = std::atof(line.c_str() + comma + 1);
  }
  return times;
}

// The simulated time a run folder's resolved case gives (dem.duration), 0 when unreadable.
double simulated_duration(const fs::path &folder)
{
  std::ifstream in(folder / "case_resolved.txt");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("dem.duration ", 0) == 0 && line.find('=') != std::string::npos)
    {
      try
      {
        return parse_quantity(line.substr(line.find('=') + 1), Dimension::time);
      }
      catch (const std::exception &)
      {
        return 0.0;
      }
    }
  return 0.0;
}

// Stage times to announce as ETAs when this run folder has none yet (a variant's first run):
// those of the newest other run of the same case beside it (its baseline or another variant),
// the DEM's scaled by the simulated time, which its cost follows nearly in proportion. `from`
// names that folder; empty when there is none.
struct StageEstimates
{
  std::map<std::string, double> seconds;
  std::string from;
};

StageEstimates estimates_from_a_sibling(const Case &c)
{
  StageEstimates e;
  const fs::path folder = c.output.directory;
  const fs::path parent = folder.parent_path().empty() ? fs::path(".") : folder.parent_path();
  std::error_code ec;
  fs::file_time_type newest{};
  fs::path best;
  for (const auto &entry : fs::directory_iterator(parent, ec))
  {
    const std::string n = entry.path().filename().string();
    if (entry.path().filename() == folder.filename() || (n != c.name && n.rfind(c.name + "-", 0) != 0))
      continue;
    const fs::path times = entry.path() / "run_times.csv";
    if (fs::exists(times, ec) && (best.empty() || fs::last_write_time(times, ec) > newest))
    {
      best = entry.path();
      newest = fs::last_write_time(times, ec);
    }
  }
  if (best.empty())
    return e;
  e.seconds = read_run_times(best / "run_times.csv");
  const double theirs = simulated_duration(best);
  if (e.seconds.count("dem"))
  {
    if (theirs > 0.0 && c.dem.duration > 0.0)
      e.seconds["dem"] *= c.dem.duration / theirs;
    else
      e.seconds.erase("dem");
  }
  e.from = best.string();
  return e;
}

void write_run_times(const fs::path &path, const std::vector<std::pair<std::string, double>> &timings)
{
  fs::create_directories(path.parent_path());
  write_file_atomically(path.string(), [&](std::ostream &out) {
    out << "stage,seconds\n";
    for (const auto &[name, dt] : timings)
      out << name << "," << dt << "\n";
  });
}

// Where everything is, with a mark for what this run produced or found.
void print_outputs(const Case &c)
{
  const fs::path results = c.output.directory;
  std::vector<std::pair<std::string, fs::path>> items = {
      {"resolved case", results / "case_resolved.txt"},
      {"overrides of this variant", results / "variant.txt"},
      {"meshes (Gmsh)", fs::path("meshes") / c.name},
      {"magnetic field grid (HDF5)", field::magnetic_grid_path(c)},
      {"magnetic field (ParaView)", field::field_file(c, "magnetic_0.pvtu")},
      {"sleeve flux profile (CSV)", field::field_file(c, "profile_sleeve.csv")},
      {"particles (ParaView)", results / "dem" / "particles.xdmf"},
      {"DEM time series (CSV)", results / "dem" / "time_series.csv"},
      {"nip profile (CSV)", results / "dem" / "nip_profile.csv"},
      {"nip key numbers (CSV)", results / "dem" / "nip_summary.csv"},
      {"chain inclination (CSV)", results / "dem" / "chain_inclination.csv"},
      {"brush height (CSV)", results / "dem" / "brush_height.csv"},
      {"nip bead budget (CSV)", results / "dem" / "nip_time_series.csv"},
      {"DEM log", results / "dem" / "dem.log"},
      {"checkpoint (restart)", results / "dem" / "checkpoint.bin"},
      {"report", results / "report" / "index.html"}};
  if (c.electric.enabled)
    items.insert(items.begin() + 3, {"electric field grid (HDF5)", field::electric_grid_path(c)});
  std::cout << "outputs:\n";
  for (const auto &[what, path] : items)
    if (fs::exists(path))
      std::printf("  %-28s %s\n", what.c_str(), path.string().c_str());
}

// After a valid check: the whole resolved case and the variant's overrides written into the
// run folder, and the case in ten lines on the terminal.
std::string describe_the_run_folder(const Case &c, const std::string &case_path)
{
  const fs::path folder = c.output.directory;
  fs::create_directories(folder);
  const fs::path resolved_file = folder / "case_resolved.txt";
  write_text_atomically(resolved_file.string(),
                        "# case " + c.name + " as resolved for this run (" + case_path + ")\n" + format_case(c));
  write_text_atomically((folder / "variant.txt").string(), variant_text(case_path, c.output.overrides));
  return case_at_a_glance(c, resolved_file.string());
}

// Stage names from --only / --skip ("field,dem"), each checked against the pipeline.
std::vector<std::string> stage_list(const cli::ParsedArguments &args, const std::string &option)
{
  if (!args.has(option))
    return {};
  const std::vector<std::string> names = split_commas(args.value(option));
  for (const auto &name : names)
    if (!contains(pipeline_stages(), name))
    {
      std::string stages;
      for (const auto &stage : pipeline_stages())
        stages += (stages.empty() ? "" : ", ") + stage;
      throw cli::UsageError(option + ": unknown stage '" + name + "' (the stages: " + stages + ")");
    }
  return names;
}

// The words a stage is run with: its name, the case, the options it declares, and the
// overrides `run` adds itself (--quick's), after the user's.
std::vector<std::string> stage_arguments(const Subcommand &stage, const cli::ParsedArguments &args,
                                         const std::vector<std::string> &added_overrides)
{
  std::vector<std::string> words = {stage.name, args.positional(0)};
  const auto options = cli::forward_options(args, stage.command_line());
  words.insert(words.end(), options.begin(), options.end());
  if (stage.command_line().find("--set"))
    for (const auto &o : added_overrides)
    {
      words.push_back("--set");
      words.push_back(o);
    }
  return words;
}

const cli::CommandSpec &run_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush run";
    s.usage = "magbrush run CASE [--set key=value ...] [--quick] [--only STAGE[,STAGE]] [--skip STAGE[,STAGE]]\n"
              "                    [options of the stages]";
    s.description = R"(Runs the whole pipeline on one case, in order:
  check   validate the case (file, line, key, unit, range); prints the case in ten lines and
          writes the whole resolved case to <run folder>/case_resolved.txt
  mesh    the Gmsh meshes of the roller and the nip, for inspection: no later stage reads them
          (the field solver meshes the case itself), so `run` skips it unless --only names it
  field   solve the magnetic and electric fields, store them as grids (reused when
          the field-relevant inputs are unchanged)
  dem     run the particles on the stored fields (its log is kept in <run folder>/dem/dem.log)
  report  plots, key numbers and ParaView links: <run folder>/report/index.html
The run folder is output.directory when the case or a --set names it, else results/<case> and,
for a run with --set overrides, results/<case>-<6 hex digits of the sorted overrides> with
the overrides listed in its variant.txt: variants of a case land side by side (compare them
with `magbrush compare`), and a variant that changes no field reads its baseline's fields.
--set goes to every stage (e.g. --set drum.gap=0.3mm); every other option only to the stages
that declare it, named in brackets below (e.g. -np 2 to the field solver, --threads 4 to the DEM).
Each stage is announced with the wall time it took in the last run of this folder (its ETA) or,
on a first run, in the newest run of the same case beside it (the DEM's scaled by the simulated
time); the DEM prints its own progress with an ETA. Stage times go to <run folder>/run_times.csv. At
the end: the time per stage and where every output is.
)";
    s.examples = {{"magbrush run cases/kawamoto_nip_fed.yaml --quick", "a first look in about a minute"},
                  {"magbrush run cases/kawamoto_nip_fed.yaml --quick --set drum.gap=0.5mm",
                   "the same with a wider gap, in its own folder (results/kawamoto_nip_fed-<digest>/)"},
                  {"magbrush run cases/kawamoto_nip_fed.yaml", "the full run (~10-15 min on 2 cores)"}};
    s.exit_status = "0 done, else the failing stage's (1 an invalid case or a failed stage, 2 bad usage).";
    s.positionals = {{"CASE", "the case file"}};
    s.options = {cli::set_option(),
                 {"--quick", {}, "",
                  "a first look in about a minute: dem.duration cut to " + std::to_string(std::lround(quick_duration * 1e3)) +
                      " ms and every averaging window\n"
                      "and spin-up scaled by the same factor (printed; they are --set overrides, so the\n"
                      "run has its own folder)",
                  false, {}, /*for_pipeline=*/false},
                 {"--only", {}, "STAGE[,STAGE]", "run only these stages"},
                 {"--skip", {}, "STAGE[,STAGE]", "skip these stages"}};
    const auto of_stages = stage_options();
    s.options.insert(s.options.end(), of_stages.begin(), of_stages.end());
    return s;
  }();
  return spec;
}

int run_stages(const cli::ParsedArguments &args)
{
  const std::vector<std::string> only = stage_list(args, "--only"), skip = stage_list(args, "--skip");
  std::vector<std::string> overrides = args.values("--set");
  // The resolved case tells where the outputs go (a bad case is reported by `check` below).
  std::optional<Case> resolved;
  try
  {
    resolved = load_case(args.positional(0), overrides);
  }
  catch (const std::exception &)
  {
  }
  // --quick: the case's own times scaled, as overrides after the user's (a user's --set of a
  // window is scaled like the file's value, since it is read from the resolved case).
  std::vector<std::string> added;
  if (args.has("--quick") && resolved)
  {
    const auto changes = quick_preset(*resolved);
    if (changes.empty())
      std::cout << "magbrush run --quick: dem.duration is already " << resolved->dem.duration * 1e3
                << " ms: nothing to shorten\n";
    else
    {
      std::cout << "magbrush run --quick: a first look, every time of the run scaled by "
                << changes.front().to / changes.front().from << " (results are not steady-state figures):\n"
                << describe(changes) << quick_caveats(*resolved, changes);
      for (const auto &q : changes)
        added.push_back(q.override_text());
      overrides.insert(overrides.end(), added.begin(), added.end());
      try
      {
        resolved = load_case(args.positional(0), overrides);
      }
      catch (const std::exception &)
      {
        resolved.reset();
      }
    }
  }
  const fs::path times_file = resolved ? fs::path(resolved->output.directory) / "run_times.csv" : fs::path();
  const auto last_times = resolved ? read_run_times(times_file) : std::map<std::string, double>{};
  const StageEstimates sibling = resolved && last_times.empty() ? estimates_from_a_sibling(*resolved) : StageEstimates{};

  const std::vector<std::string> &pipeline = pipeline_stages();
  std::vector<std::pair<std::string, double>> timings;
  std::vector<std::string> unavailable;
  const auto t_start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < pipeline.size(); ++k)
  {
    const std::string &name = pipeline[k];
    if ((!only.empty() && !contains(only, name)) || contains(skip, name))
      continue;
    // The Gmsh meshes are for inspection: no later stage reads them (the field solver meshes
    // the case itself, a magnetic blade's mesh included), so they cost ~20 s for nothing.
    if (name == "mesh" && !contains(only, name))
    {
      std::cout << "\n== magbrush run: stage " << k + 1 << "/" << pipeline.size()
                << ": mesh skipped: no later stage reads the Gmsh meshes (the field solver meshes the case "
                   "itself); `magbrush mesh CASE` or --only mesh writes them ==" << std::endl;
      continue;
    }
    const Subcommand *stage = find_subcommand(name);
    if (!stage)
    {
      unavailable.push_back(name);
      continue;
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::ostringstream eta;
    if (last_times.count(name))
      eta << ", ETA ~" << static_cast<long>(last_times.at(name) + 0.5) << " s (last run)";
    // A variant may solve its own fields or none; the check takes no time worth announcing.
    else if (sibling.seconds.count(name) && name != "field" && name != "check")
      eta << ", ETA ~" << static_cast<long>(sibling.seconds.at(name) + 0.5) << " s (from " << sibling.from
          << (name == "dem" ? ", scaled by the simulated time)" : ")");
    std::cout << "\n== magbrush run: stage " << k + 1 << "/" << pipeline.size() << ": " << name << " (at "
              << static_cast<long>(elapsed) << " s" << eta.str() << ") ==" << std::endl;
    if (name == "dem" && resolved && resolved->dem.settle_time > 0.0)
      std::cout << "(the engine settles the beads for " << resolved->dem.settle_time * 1e3
                << " ms with the walls at rest before its progress lines start)" << std::endl;
    std::vector<std::string> a = stage_arguments(*stage, args, added);
    // `check` validates quietly: its errors still print, the resolved case goes to a file.
    if (name == "check" && stage->command_line().find("--quiet"))
      a.push_back("--quiet");
    const auto t0 = std::chrono::steady_clock::now();
    int rc = 0;
    if (name == "dem" && resolved)
    {
      const fs::path dem_dir = fs::path(resolved->output.directory) / "dem";
      fs::create_directories(dem_dir);
      // A resumed DEM continues its log: the earlier runs' lines stay above its own.
      const bool resuming = args.has("--resume") && fs::exists(dem_dir / "checkpoint.bin");
      TeeOutput tee((dem_dir / "dem.log").string(), resuming);
      rc = stage->run(a);
    }
    else
      rc = stage->run(a);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    timings.emplace_back(name, dt);
    if (resolved && name != "check")
      write_run_times(times_file, timings);
    if (rc != 0)
    {
      std::cerr << "magbrush run: stage '" << name << "' failed (exit " << rc
                << "); later stages not run. Outputs of earlier stages are kept.\n";
      return rc;
    }
    if (name == "check" && resolved)
      std::cout << describe_the_run_folder(*resolved, args.positional(0));
  }

  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::cout << "\n== magbrush run: done in " << total << " s ==\n";
  for (const auto &[name, dt] : timings)
    std::printf("  %-7s %8.2f s\n", name.c_str(), dt);
  if (!unavailable.empty())
  {
    std::cout << "  not in this build yet:";
    for (const auto &n : unavailable)
      std::cout << " " << n;
    std::cout << "\n";
  }
  if (resolved)
    print_outputs(*resolved);
  return 0;
}

} // namespace

const std::vector<std::string> &pipeline_stages()
{
  static const std::vector<std::string> stages = {"check", "mesh", "field", "dem", "report"};
  return stages;
}

std::vector<cli::Option> stage_options()
{
  std::vector<cli::Option> options;
  std::vector<std::vector<std::string>> declared_by; // the stages of options[k]
  auto taken = [&](const cli::Option &o) -> cli::Option * {
    for (auto &existing : options)
      if (existing.is_called(o.name))
        return &existing;
    return nullptr;
  };
  for (const auto &name : pipeline_stages())
  {
    const Subcommand *stage = find_subcommand(name);
    if (!stage)
      continue;
    for (const cli::Option &o : stage->command_line().options)
    {
      if (!o.for_pipeline || o.name == "--set")
        continue;
      if (cli::Option *existing = taken(o))
        declared_by[static_cast<std::size_t>(existing - options.data())].push_back(name);
      else
      {
        options.push_back(o);
        declared_by.push_back({name});
      }
    }
  }
  for (std::size_t k = 0; k < options.size(); ++k)
  {
    std::string stages;
    for (const auto &name : declared_by[k])
      stages += (stages.empty() ? "" : ", ") + name;
    options[k].help += " [" + stages + "]";
  }
  return options;
}

int run_pipeline(const std::vector<std::string> &args)
{
  return cli::run_command(run_command_line(), {args.begin() + 1, args.end()}, run_stages);
}

namespace {
const bool registered = register_subcommand(
    {"run", "the whole pipeline: check, field, dem, report (mesh on request); --quick for a first look", run_pipeline,
     run_command_line, 90});
} // namespace

} // namespace magbrush
