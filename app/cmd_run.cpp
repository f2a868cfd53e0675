// `magbrush run CASE`: the whole pipeline — validate, mesh, fields, DEM, report — each stage
// skipped when its outputs are up to date (the stages themselves decide that), with progress
// and an ETA at every stage, the wall time of every stage, and at the end a summary of where
// every output is.
//
//   for each stage: announce it (with the time it took last time: its ETA) → run it; the DEM's
//   output is also kept in <output.directory>/dem/dem.log (the report reads its timing table)
//   → record the stage's wall time in <output.directory>/run_times.csv
//   then: the table of times, and the list of outputs with their paths.
#include "run_pipeline.h"
#include "subcommand.h"

#include "case_parser.h"
#include "field_files.h"

#include <chrono>
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

const char *run_help =
    R"(Usage: magbrush run CASE [--set key=value ...] [--only STAGE[,STAGE]] [--skip STAGE[,STAGE]]

Runs the whole pipeline on one case, in order:
  check   validate the case (file, line, key, unit, range)
  mesh    write the Gmsh meshes of the roller and the nip
  field   solve the magnetic and electric fields, store them as grids (reused when
          the field-relevant inputs are unchanged)
  dem     run the particles on the stored fields (its log is kept in <output.directory>/dem/dem.log)
  report  plots, key numbers and ParaView links: <output.directory>/report/index.html
Options after CASE are passed to every stage (e.g. --set drum.gap=0.3mm).
Each stage is announced with the wall time it took in the last run of this case (its ETA); the
DEM prints its own progress with an ETA. Stage times go to <output.directory>/run_times.csv. At
the end: the time per stage and where every output is.
)";

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

const Subcommand *find_stage(const std::string &name)
{
  for (const auto &c : subcommands())
    if (c.name == name)
      return &c;
  return nullptr;
}

// Copies everything this process (and its children) write to stdout/stderr into a log file
// as well, while it lives: fd 1 and 2 go to a pipe that a thread drains into both.
class TeeOutput
{
public:
  explicit TeeOutput(const std::string &log_path) : log_(log_path)
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

void write_run_times(const fs::path &path, const std::vector<std::pair<std::string, double>> &timings)
{
  fs::create_directories(path.parent_path());
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream o(tmp);
    o << "stage,seconds\n";
    for (const auto &[name, dt] : timings)
      o << name << "," << dt << "\n";
  }
  fs::rename(tmp, path);
}

// Where everything is, with a mark for what this run produced or found.
void print_outputs(const Case &c)
{
  const fs::path results = c.output.directory;
  std::vector<std::pair<std::string, fs::path>> items = {
      {"meshes (Gmsh)", fs::path("meshes") / c.name},
      {"magnetic field grid (HDF5)", field::magnetic_grid_path(c)},
      {"magnetic field (ParaView)", field::field_file(c, "magnetic_0.pvtu")},
      {"sleeve flux profile (CSV)", field::field_file(c, "profile_sleeve.csv")},
      {"particles (ParaView)", results / "dem" / "particles.xdmf"},
      {"DEM time series (CSV)", results / "dem" / "time_series.csv"},
      {"nip profile (CSV)", results / "dem" / "nip_profile.csv"},
      {"nip key numbers (CSV)", results / "dem" / "nip_summary.csv"},
      {"chain inclination (CSV)", results / "dem" / "chain_inclination.csv"},
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

} // namespace

int run_pipeline(const std::vector<std::string> &args)
{
  std::vector<std::string> stage_args; // CASE and the options every stage understands
  std::vector<std::string> only, skip, overrides;
  for (size_t i = 1; i < args.size(); ++i)
  {
    if (args[i] == "--help" || args[i] == "-h")
    {
      std::cout << run_help;
      return 0;
    }
    if ((args[i] == "--only" || args[i] == "--skip") && i + 1 < args.size())
    {
      (args[i] == "--only" ? only : skip) = split_commas(args[i + 1]);
      ++i;
      continue;
    }
    if (args[i] == "--set" && i + 1 < args.size())
      overrides.push_back(args[i + 1]);
    else if (args[i].rfind("--set=", 0) == 0)
      overrides.push_back(args[i].substr(6));
    stage_args.push_back(args[i]);
  }
  if (stage_args.empty() || stage_args[0].empty() || stage_args[0][0] == '-')
  {
    std::cerr << run_help;
    return 2;
  }
  // The resolved case tells where the outputs go (a bad case is reported by `check` below).
  std::optional<Case> resolved;
  try
  {
    resolved = load_case(stage_args[0], overrides);
  }
  catch (const std::exception &)
  {
  }
  const fs::path times_file = resolved ? fs::path(resolved->output.directory) / "run_times.csv" : fs::path();
  const auto last_times = resolved ? read_run_times(times_file) : std::map<std::string, double>{};

  const std::vector<std::string> pipeline = {"check", "mesh", "field", "dem", "report"};
  std::vector<std::pair<std::string, double>> timings;
  std::vector<std::string> unavailable;
  const auto t_start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < pipeline.size(); ++k)
  {
    const std::string &name = pipeline[k];
    if ((!only.empty() && !contains(only, name)) || contains(skip, name))
      continue;
    const Subcommand *stage = find_stage(name);
    if (!stage)
    {
      unavailable.push_back(name);
      continue;
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::ostringstream eta;
    if (last_times.count(name))
      eta << ", ETA ~" << static_cast<long>(last_times.at(name) + 0.5) << " s (last run)";
    std::cout << "\n== magbrush run: stage " << k + 1 << "/" << pipeline.size() << ": " << name << " (at "
              << static_cast<long>(elapsed) << " s" << eta.str() << ") ==" << std::endl;
    if (name == "dem" && resolved && resolved->dem.settle_time > 0.0)
      std::cout << "(the engine settles the beads for " << resolved->dem.settle_time * 1e3
                << " ms with the walls at rest before its progress lines start)" << std::endl;
    std::vector<std::string> a = {name};
    a.insert(a.end(), stage_args.begin(), stage_args.end());
    const auto t0 = std::chrono::steady_clock::now();
    int rc = 0;
    if (name == "dem" && resolved)
    {
      const fs::path dem_dir = fs::path(resolved->output.directory) / "dem";
      fs::create_directories(dem_dir);
      TeeOutput tee((dem_dir / "dem.log").string());
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

namespace {
const bool registered = register_subcommand(
    {"run", "the whole pipeline: check, mesh, field, dem, report", run_pipeline, 90});
} // namespace

} // namespace magbrush
