// `magbrush sweep CASE --vary key=v1,v2,... [--vary ...]`: the pipeline once per point of a
// parameter sweep, each point in its own output folder, then every point's key numbers in one
// table and plot: Kawamoto's nip studies (Fig. 22–27: carrier diameter, supplied layer,
// development gap), Kweon's TMA against the bias and DMA against the blade gap.
//
//   points = the Cartesian product of the --vary lists (a --with list moving together with the
//   first --vary, value for value) → for each: its overrides (a carrier
//   diameter also rescales the bead count so that the supplied volume — the layer — stays the
//   same) → `magbrush run` with output.directory and field.output_dir inside the point's
//   folder, timed → gather every point's dem/summary.csv (whatever its measurements report,
//   with standard errors and the steady-state verdict) into sweep_summary.csv
//   (common/study_table.h), with a measured series compared when given, and the nip profiles
//   into sweep_profiles.csv → tools/plot_sweep.py draws each key against the varied value
//   (error bars, the physical bound, the measured points) and the profiles side by side.
//
// Where the points run: serially (a plain `magbrush sweep`), on the ranks of an MPI job
// (`mpirun -np K magbrush sweep`, the points dealt back and forth over the ranks: app/sweep_ranks.h), or as the tasks of
// a Slurm job array (`--emit slurm` writes it, app/sweep_slurm.h; each task runs `--point i`).
// Each point leaves its run time and status in <point>/sweep_point.csv, and the table is built
// from the point folders by one process (the serial sweep, rank 0 after every rank finished, or
// `--merge`): the same code, so the same table wherever the points ran.
#include "app/run_pipeline.h"
#include "app/subcommand.h"
#include "app/sweep_ranks.h"
#include "app/sweep_slurm.h"
#include "app/sweep_spin_up.h"

#include "case/case_hash.h"
#include "case/case_parser.h"
#include "case/case_schema.h"
#include "case/run_folder.h"
#include "case/units.h"
#include "common/atomic_file.h"
#include "common/child_process.h"
#include "common/study_repeats.h"
#include "common/study_table.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

// The options, declared once: the parser reads them (common/command_line.h). Besides its
// own, sweep accepts the options of the pipeline's stages and hands them to `magbrush run`.
const cli::CommandSpec &sweep_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush sweep";
    s.usage = "magbrush sweep CASE --vary key=v1,v2[,...] [--vary key=...] [--set key=value ...]\n"
              "                      [--repeats N] [--name NAME] [--no-keep-layer] [--skip STAGE[,STAGE]]\n"
              "                      [options of the stages]\n"
              "                      [--point INDEX | --merge | --emit slurm]\n"
              "       mpirun -np K magbrush sweep CASE --vary ...";
    s.description = R"(Runs the pipeline (check, field, dem, report; the Gmsh meshes are not needed per point) once
for every combination of the --vary values (a --with key goes value for value with the first
--vary), each point in results/sweep_<NAME>/<point>/ (<output.directory>/sweep_<NAME>/<point>/
when the case names a folder; the point's dem/ and report/; the stored fields in
sweep_<NAME>/fields/<digests of the field inputs>/, solved once for the points that share them),
then compares the nip profiles of all points:
  sweep_summary.csv    one row per point: the varied values (as given and in SI), the bead
                       count, every key number the point's measurements report (dem/summary.csv:
                       e.g. slip at the gap centre, normal force per length, TMA, DMA) with its
                       standard error (<key>_stderr) and, for the keys the steady-state test
                       looked at, the drift between the halves of the averaging window with its
                       standard error (<key>_drift, <key>_drift_stderr), steady_state (1: every tested mean drifts < 2 %;
                       where a measurement reports a state, e.g. the beads in the nip window: the
                       state drifts < 2 % and no other mean drifts beyond 2 % and its noise, or
                       beyond 2 % with too few samples to know its noise),
                       significant_drift (1: a drift beyond two of its standard errors, a
                       trend; 0: noise) and drift_resolution, the run time of the point, and with --measured the measured value, the
                       relative error and a within-tolerance flag
  sweep_mean.csv       with --repeats N: one row per point, every key's mean over its N
                       repeats (dem.seed = the case's seed + 0 .. N-1, the last varied key of
                       sweep_summary.csv) with the standard error from the spread between the
                       repeats (<key>_stderr: what a short or transient run needs; a run's own
                       block-averaged error sees only its window), the drifts averaged, the
                       verdicts combined (steady only when every repeat is), the repeats that
                       ran, the summed run time; the plots then show these means
  sweep_profiles.csv   every point's profile along the nip (long format), for nip scenes
  sweep_<key>.png      each key with a standard error against the (first) varied value, with
                       its physical bound (<key>_bound), the measured points and, per point,
                       the key's own steady-state verdict, the run's and the run time
  sweep_tma_threshold.csv   a TMA study against electric.bias: the straight line through its
                       points (weighted by their standard errors), its slope and the bias where
                       it reaches zero (the development threshold) with their standard errors,
                       chi2/dof, and the bias where the contrast vanishes; drawn in the TMA plot
  sweep_slip.png, sweep_pressure.png, sweep_density.png   (Kawamoto Fig. 17-19, 22-27)
Values carry units as in the case file (--vary populations.carrier.diameter=42um,50um,60um).
Varying a population's diameter also scales its count by (d0/d)^3 and its diameter_std by
d/d0, so that the supplied carrier volume (the layer) stays the same, as in the paper's
42/50/60 um comparison, and a fixed dem.time_step by d/d0 (the stable step is proportional to
the bead size); a population supplied by the inflow or given by its mass (count 0) keeps its
volume by itself, and its diameter_std and the step still scale; --no-keep-layer switches
all of that off.
The options of the stages (named in brackets) go to the stages that declare them, at every point.

Beyond one process (the points are independent; the table is the same bit for bit but for
run_time_s):
  mpirun -np K magbrush sweep ...   the points are dealt in rounds of K, forwards then backwards
                       (K = 2: points 0, 3, 4, 7, ... on rank 0), which balances the ranks when
                       the cost grows along the values; rank 0 writes the table, the
                       profiles and the plots once every rank has finished. Each rank's DEM gets
                       --threads if given, else its share of the node: min(the cores mpirun
                       binds it to, the node's cores / its ranks on the node). OpenMPI binds
                       each rank to one core at -np 2: add --bind-to none (or --map-by
                       slot:PE=N) for more threads per rank. The field stage's -np N still
                       starts its own mpirun from inside a rank (a job of its own).
  --emit slurm         writes sweep_<NAME>.slurm (a job array, task i runs --point i) and
                       sweep_<NAME>_merge.slurm (--merge, submitted with
                       --dependency=afterok on the array) into the sweep's folder, and prints
                       the sbatch line; edit the resource lines first.
  --point INDEX / --merge   the two steps by hand (a point's run time and status are kept in
                       its folder, <point>/sweep_point.csv).
  --spin-up DURATION --settle DURATION
                       build the scene once (the case at the --set values, to t = DURATION, in
                       sweep_<NAME>/spin_up/; reused when it finished with the same case) and fork
                       every point from its checkpoint (--restart --restart-anyway: the point's
                       values act from the fork on). The points' averages (every measurement's
                       average_from) start no earlier than DURATION + settle, when what the
                       spin-up's values left in the scene has passed the measured region; without
                       --settle the sweep says what the speeds give. Each point's sweep_point.csv
                       names the spin-up it came from; dem.duration stays the points' end time.
  --resume             a point stopped before its end (a time limit, by hand, a crash) continues
                       from its own dem/checkpoint.bin, its files then covering the whole run;
                       one without a checkpoint starts afresh, a finished one only rewrites its
                       files. Its run time adds the time spent before (to the last line of its
                       DEM log when it was stopped). A merge lists the points still "running".
)";
    s.positionals = {{"CASE", "the case file"}};
    s.options = {{"--vary", {}, "key=v1,v2", "the values of one key to run (repeatable: every combination)", true},
                 {"--with", {}, "key=v1,v2", "a key whose values go with the first --vary's, value for value (as\n"
                                             "many values; repeatable): one point per pair, not every combination", true},
                 cli::set_option(),
                 {"--repeats", {}, "N", "run every point N times with other seeds (dem.seed + 0 .. N-1) and tabulate\n"
                                        "their means with the standard error of their spread (sweep_mean.csv)"},
                 {"--name", {}, "NAME", "the sweep's folder is sweep_NAME (default: the varied keys' names)"},
                 {"--no-keep-layer", {}, "", "do not rescale the count, diameter_std and time step with a diameter"},
                 {"--skip", {}, "STAGE[,STAGE]", "stages not run at each point (default: mesh)"},
                 {"--measured", {}, "FILE", "a measured series to compare: CSV with the varied key and a summary key "
                                            "as columns (e.g. electric.bias,tma_kg_per_m2; values in SI or with units)"},
                 {"--tolerance", {}, "FRACTION", "relative error counted as agreement with --measured (default 0.1)"},
                 {"--point", {}, "INDEX", "run only point INDEX (0-based, in the order of the table) and keep its\n"
                                          "result in its folder: one task of a job array; --merge builds the table"},
                 {"--merge", {}, "", "run nothing: the table, profiles and plots from the points' folders"},
                 {"--spin-up", {}, "DURATION", "run the case once to t = DURATION and fork every point from its end"},
                 {"--settle", {}, "DURATION", "with --spin-up: the points average from DURATION + settle on"},
                 {"--emit", {}, "slurm", "run nothing: write a Slurm job array (one task per point, --point) and its\n"
                                         "merge step (--merge) into the sweep's folder", false, {"slurm"}}};
    const auto of_stages = stage_options();
    s.options.insert(s.options.end(), of_stages.begin(), of_stages.end());
    s.examples = {{"magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.diameter=42um,50um,60um",
                   "Kawamoto Fig. 22-23: the carrier diameter"},
                  {"magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.count=9000,12300,15000",
                   "Fig. 24-25: the amount of developer"},
                  {"magbrush sweep cases/kawamoto_nip.yaml --vary drum.gap=0.3mm,0.4mm,0.5mm", "Fig. 26-27: the gap"},
                  {"magbrush sweep cases/kweon_development.yaml --vary electric.bias=-500V,-600V,-700V,-800V,-800V "
                   "--with electric.image.duty=1,1,1,1,0 --spin-up 8ms --settle 8.5ms",
                   "Kweon Fig. 9: the TMA at four biases and the fog (a dark drum) at the last, one spin-up"}};
    s.exit_status = "0 every point done, 1 an invalid case or a failed point, 2 bad usage.";
    return s;
  }();
  return spec;
}

// The stages' options given to the sweep, as words for `magbrush run`.
std::vector<std::string> options_for_the_stages(const cli::ParsedArguments &args)
{
  cli::CommandSpec stages;
  stages.options = stage_options();
  return cli::forward_options(args, stages);
}

struct Vary
{
  std::string key;
  std::vector<std::string> values;
  int follows = -1; // a --with key: the index of the --vary whose value index it takes (else -1)
};

std::vector<std::string> split(const std::string &s, char sep)
{
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty())
      out.push_back(item);
  return out;
}

// A folder-safe label: key tail and value ("diameter-42um").
std::string label_of(const std::string &key, const std::string &value)
{
  std::string tail = key.substr(key.find_last_of('.') + 1) + "-" + value;
  for (char &ch : tail)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '.')
      ch = '_';
  return tail;
}

// The population addressed by "populations.<name or [i]>.<leaf>", or nullptr.
const Population *population_of(const Case &c, const std::string &key, std::string &selector)
{
  static const std::regex pattern(R"(^populations\.([^.]+)\.[A-Za-z_]+$)");
  std::smatch m;
  if (!std::regex_match(key, m, pattern))
    return nullptr;
  selector = m[1];
  if (selector.size() > 2 && selector.front() == '[' && selector.back() == ']')
  {
    const auto i = static_cast<std::size_t>(std::atol(selector.substr(1, selector.size() - 2).c_str()));
    return i < c.populations.size() ? &c.populations[i] : nullptr;
  }
  for (const auto &p : c.populations)
    if (p.name == selector)
      return &p;
  return nullptr;
}

// "key=v1,v2,..." of one --vary.
Vary parse_vary(const std::string &v)
{
  const auto eq = v.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 >= v.size())
    throw cli::UsageError("--vary expects key=v1,v2,... (e.g. --vary drum.gap=0.3mm,0.4mm), found '" + v + "'");
  return {v.substr(0, eq), split(v.substr(eq + 1), ',')};
}

// The case key's declaration for an override path: a list entry or a map entry is addressed
// by its name, so "populations.carrier.diameter" is declared as "populations[].diameter",
// "roller.poles.S2.angle" as "roller.poles[].angle", "materials.toner.hamaker" as
// "materials.*.hamaker". Each inner segment is tried as such a name.
const KeySpec *spec_of_path(const std::string &path)
{
  if (const KeySpec *s = find_key_spec(path))
    return s;
  const std::vector<std::string> parts = split(path, '.');
  for (std::size_t named = 1; named + 1 < parts.size(); ++named)
  {
    std::string head = parts[0], tail;
    for (std::size_t k = 1; k < named; ++k)
      head += "." + parts[k];
    for (std::size_t k = named + 1; k < parts.size(); ++k)
      tail += "." + parts[k];
    for (const std::string &pattern : {head + "[]" + tail, head + ".*" + tail})
      if (const KeySpec *s = find_key_spec(pattern))
        return s;
  }
  return nullptr;
}

// A varied value in SI (NaN when it is not a number): "-500V" → −500, "0.4mm" → 4e-4.
double si_value(const std::string &key, const std::string &text)
{
  const KeySpec *spec = spec_of_path(key);
  try
  {
    return parse_quantity(text, spec ? spec->dimension : Dimension::dimensionless, BareNumber::si);
  }
  catch (const std::exception &)
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

std::string si_header(const std::string &key)
{
  const KeySpec *spec = spec_of_path(key);
  const std::string unit = spec ? si_unit(spec->dimension) : "";
  return key + " [" + (unit.empty() ? "1" : unit) + "]";
}

// A measured series: CSV with the varied key (values in SI or with units) and a summary key.
// Read before the sweep runs, so that a malformed file costs no run.
struct MeasuredSeries
{
  std::string key;
  std::vector<std::pair<double, double>> values; // (varied value in SI, measured value)
};

MeasuredSeries read_measured(const std::string &path, const std::string &varied_key)
{
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("--measured: cannot read '" + path + "'");
  std::string line;
  std::vector<std::string> header;
  std::vector<std::pair<double, double>> values;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    const auto cells = split(line, ',');
    if (header.empty())
    {
      header = cells;
      if (header.size() != 2 || header[0] != varied_key)
        throw std::runtime_error("--measured '" + path + "': expected the header '" + varied_key +
                                 ",<summary key>' (e.g. " + varied_key + ",tma_kg_per_m2), found '" + line + "'");
      continue;
    }
    if (cells.size() != 2)
      throw std::runtime_error("--measured '" + path + "': expected two values per line, found '" + line + "'");
    const double x = si_value(varied_key, cells[0]), y = si_value("", cells[1]);
    if (std::isnan(x) || std::isnan(y))
      throw std::runtime_error("--measured '" + path + "': cannot read the numbers of '" + line + "'");
    values.emplace_back(x, y);
  }
  if (header.size() != 2)
    throw std::runtime_error("--measured '" + path + "' holds no header line");
  return {header[1], values};
}

// The measured value at each point (NaN where the series has none).
MeasuredComparison compare_with(const MeasuredSeries &series, const std::vector<double> &point_x, double tolerance)
{
  MeasuredComparison m;
  m.key = series.key;
  m.tolerance = tolerance;
  for (double x : point_x)
  {
    double y = std::numeric_limits<double>::quiet_NaN();
    for (const auto &[mx, my] : series.values)
      if (std::abs(mx - x) <= 1e-9 * std::max(std::abs(x), 1e-300))
        y = my;
    m.measured.push_back(y);
  }
  return m;
}

// --repeats' value: a whole number of runs per point, 1 (the default) to 1000.
std::size_t repeats_of(const cli::ParsedArguments &args)
{
  const std::string text = args.value("--repeats", "1");
  char *end = nullptr;
  const long long n = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || n < 1 || n > 1000)
    throw cli::UsageError("--repeats expects a whole number of runs per point, 1 to 1000, found '" + text + "'");
  return static_cast<std::size_t>(n);
}

// The sweep as its arguments define it: the same in every process that takes part (each MPI
// rank, each Slurm array task, the merge step), so that point n is the same point everywhere.
struct SweepPlan
{
  std::string case_path, skip, name;
  std::vector<std::string> overrides;
  bool keep_layer = true;
  std::vector<Vary> vary;
  std::optional<MeasuredSeries> measured;
  double tolerance = 0.1;
  std::size_t repeats = 1; // > 1: the last entry of vary is dem.seed, one value per repeat
  Case base;
  fs::path sweep_dir;
  std::vector<std::vector<std::size_t>> points; // per point: the index of its value of each --vary
  std::optional<SweepSpinUp> spin_up;           // --spin-up: every point forks from it
};

SweepPlan plan_sweep(const cli::ParsedArguments &args)
{
  SweepPlan plan;
  plan.case_path = args.positional(0);
  plan.skip = args.value("--skip", "mesh");
  plan.name = args.value("--name");
  plan.overrides = args.values("--set");
  plan.keep_layer = !args.has("--no-keep-layer");
  for (const auto &v : args.values("--vary"))
    plan.vary.push_back(parse_vary(v));
  if (plan.vary.empty())
    throw cli::UsageError("nothing to vary: give --vary key=v1,v2,...");
  const std::size_t leaders = plan.vary.size();
  for (const auto &v : args.values("--with"))
  {
    Vary with = parse_vary(v);
    if (with.values.size() != plan.vary[0].values.size())
      throw cli::UsageError("--with " + with.key + " gives " + std::to_string(with.values.size()) +
                            " values; they go value for value with the first --vary (" + plan.vary[0].key + "), which has " +
                            std::to_string(plan.vary[0].values.size()));
    with.follows = 0;
    plan.vary.push_back(with);
  }
  plan.tolerance = std::atof(args.value("--tolerance", "0.1").c_str());
  if (args.has("--measured") && leaders > 1)
    throw cli::UsageError("--measured compares along one varied key; this sweep varies " + std::to_string(leaders));
  if (!(plan.tolerance > 0.0))
    throw cli::UsageError("--tolerance expects a positive fraction (0.1 = 10 %), found '" +
                          args.value("--tolerance", "") + "'");
  if (args.has("--measured"))
    plan.measured = read_measured(args.value("--measured"), plan.vary[0].key);
  plan.base = load_case(plan.case_path, plan.overrides);
  if (plan.name.empty())
    for (const auto &v : plan.vary)
      plan.name += (plan.name.empty() ? "" : "_") + v.key.substr(v.key.find_last_of('.') + 1);
  // A sweep's folder holds its points' run folders itself: under results/ when the case names
  // no folder (not under the automatic run folder of its base), else under the named one.
  plan.sweep_dir = fs::path(plan.base.output.automatic ? results_root_directory : plan.base.output.directory) /
                   ("sweep_" + plan.name);
  plan.repeats = repeats_of(args);
  if (args.has("--spin-up") && args.has("--restart"))
    throw cli::UsageError("--spin-up gives every point its restart: do not also give --restart");
  plan.spin_up = plan_spin_up(args.value("--spin-up"), args.value("--settle"), plan.base, plan.sweep_dir);
  if (plan.repeats > 1)
  {
    // The repeats are the last varied key, so that a point's repeats are neighbours in the
    // table (and their folders sit side by side: p0_..._seed-1, p1_..._seed-2, ...).
    for (const auto &v : plan.vary)
      if (v.key == "dem.seed")
        throw cli::UsageError("--repeats draws the seeds itself: do not also vary dem.seed");
    Vary seeds{"dem.seed", {}};
    for (std::size_t r = 0; r < plan.repeats; ++r)
      seeds.values.push_back(std::to_string(plan.base.dem.seed + r));
    plan.vary.push_back(seeds);
  }

  // Every combination (the last --vary runs fastest); a --with key takes its leader's index.
  plan.points.assign(1, {});
  for (const auto &v : plan.vary)
  {
    if (v.follows >= 0)
    {
      for (auto &p : plan.points)
        p.push_back(p[static_cast<std::size_t>(v.follows)]);
      continue;
    }
    std::vector<std::vector<std::size_t>> next;
    for (const auto &p : plan.points)
      for (std::size_t k = 0; k < v.values.size(); ++k)
      {
        next.push_back(p);
        next.back().push_back(k);
      }
    plan.points = next;
  }
  return plan;
}

// One point: its folder label, the overrides that make it, its case and its folder.
struct PointSetup
{
  std::string label;
  std::vector<std::string> overrides;
  Case point_case;
  fs::path dir;
};

// The stored fields go where every run with the same field inputs finds them (named by the
// digests of those inputs): a study over a blade gap, a bias or a carrier solves the roller
// field once; two ranks solving the same field at once both write atomically. Returns the
// override that puts them there.
std::string fields_override(const SweepPlan &plan, const std::vector<std::string> &overrides)
{
  const Case c = load_case(plan.case_path, overrides);
  return "field.output_dir=" +
         (plan.sweep_dir / "fields" / (field_hash(c, FieldKind::magnetic) + "_" + field_hash(c, FieldKind::electric)))
           .string();
}

// `magbrush run`'s words for one run of the sweep: the case, the stages skipped, the overrides,
// the stages' own options as the user gave them, and `threads` (> 0) unless the user gave --threads.
std::vector<std::string> run_words(const SweepPlan &plan, const std::string &skip,
                                   const std::vector<std::string> &overrides, const cli::ParsedArguments &args,
                                   int threads)
{
  std::vector<std::string> words = {"run", plan.case_path, "--skip", skip};
  for (const auto &o : overrides)
  {
    words.push_back("--set");
    words.push_back(o);
  }
  const auto stage_words = options_for_the_stages(args);
  words.insert(words.end(), stage_words.begin(), stage_words.end());
  if (threads > 0 && !args.has("--threads"))
  {
    words.push_back("--threads");
    words.push_back(std::to_string(threads));
  }
  return words;
}

PointSetup set_up_point(const SweepPlan &plan, std::size_t n)
{
  PointSetup point;
  point.overrides = plan.overrides;
  point.label = "p" + std::to_string(n);
  for (std::size_t k = 0; k < plan.vary.size(); ++k)
  {
    const std::string &key = plan.vary[k].key, &val = plan.vary[k].values[plan.points[n][k]];
    point.overrides.push_back(key + "=" + val);
    point.label += "_" + label_of(key, val);
  }
  // Keep the supplied carrier volume when a diameter changes: count × (d0/d)³, std × d/d0.
  // A population placed by mass or supplied by the inflow (count 0) keeps its volume by
  // itself (the inflow offers an areal mass); its spread and the time step still scale.
  point.point_case = load_case(plan.case_path, point.overrides);
  for (std::size_t k = 0; k < plan.vary.size() && plan.keep_layer; ++k)
  {
    std::string selector;
    const Population *p0 = population_of(plan.base, plan.vary[k].key, selector);
    if (!p0 || plan.vary[k].key.substr(plan.vary[k].key.find_last_of('.') + 1) != "diameter")
      continue;
    const Population *p1 = population_of(point.point_case, plan.vary[k].key, selector);
    const double ratio = p0->diameter_mean / p1->diameter_mean;
    if (p0->count > 0)
    {
      const long count = std::lround(static_cast<double>(p0->count) * ratio * ratio * ratio);
      point.overrides.push_back("populations." + selector + ".count=" + std::to_string(count));
    }
    char std_text[64];
    std::snprintf(std_text, sizeof std_text, "%.9g m", p0->diameter_std / ratio);
    point.overrides.push_back("populations." + selector + ".diameter_std=" + std_text);
    // The stable step scales with the bead size (Hertz contact time ∝ d): a case that fixes
    // its step keeps the same fraction of the limit.
    if (plan.base.dem.time_step > 0.0)
    {
      std::snprintf(std_text, sizeof std_text, "%.9g s", plan.base.dem.time_step / ratio);
      point.overrides.push_back("dem.time_step=" + std::string(std_text));
    }
  }
  point.dir = plan.sweep_dir / point.label;
  point.overrides.push_back("output.directory=" + point.dir.string());
  point.overrides.push_back(fields_override(plan, point.overrides));
  point.point_case = load_case(plan.case_path, point.overrides);
  return point;
}

// What the table needs of a point that its folder does not already hold (dem/summary.csv,
// dem/nip_profile.csv): its run time and status, as the table's cells. Every way of running a
// point (serially, on an MPI rank, as a Slurm task) writes it, and the table is always built
// from the folders, by whichever process merges.
constexpr const char *point_result_name = "sweep_point.csv";

// `rank`: the MPI rank that ran it (0 without mpirun), for the record (not in the table).
// `spin_up`: the spin-up the point was forked from, recorded beside its result.
void write_point_result(const fs::path &dir, const std::string &run_time_cell, const std::string &status, int rank,
                        const std::optional<SweepSpinUp> &spin_up)
{
  write_text_atomically((dir / point_result_name).string(),
                        "# magbrush sweep: this point's run, for the sweep's table\nrun_time_s,status,rank" +
                            spin_up_header_cells() + "\n" + run_time_cell + "," + status + "," +
                            std::to_string(rank) + spin_up_cells(spin_up) + "\n");
}

// {run time cell, status}; {"nan", "missing"} when the point has not (or not yet) run.
std::pair<std::string, std::string> read_point_result(const fs::path &dir)
{
  std::ifstream in(dir / point_result_name);
  std::string line;
  bool header = true;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    if (header)
    {
      header = false;
      continue;
    }
    const auto cells = split(line, ',');
    if (cells.size() >= 2)
      return {cells[0], cells[1]};
  }
  return {"nan", "missing"};
}

// The time a point has already spent, for a resumed point's run time: what its folder
// recorded, and for a run stopped before its end (still "running": killed by a time limit or
// by hand) also the time from its start (when it wrote sweep_point.csv) to the last line of
// its DEM log. 0 when the point has not run.
double time_spent_before(const fs::path &dir)
{
  const auto [run_time_cell, status] = read_point_result(dir);
  if (status == "missing")
    return 0.0;
  const double recorded = std::atof(run_time_cell.c_str());
  const double earlier = std::isfinite(recorded) ? recorded : 0.0;
  const fs::path log = dir / "dem" / "dem.log";
  if (status != "running" || !fs::exists(log))
    return earlier;
  const auto stopped = fs::last_write_time(log) - fs::last_write_time(dir / point_result_name);
  return earlier + std::max(0.0, std::chrono::duration<double>(stopped).count());
}

std::string seconds_cell(double seconds)
{
  char cell[64];
  std::snprintf(cell, sizeof cell, "%.1f", seconds);
  return cell;
}

// Runs point n's pipeline in its folder and keeps its result there; returns the pipeline's
// exit code. `threads` > 0: the DEM's --threads when the user gave none (an MPI rank's share).
// A point that throws counts as failed rather than ending the process: on an MPI rank an
// escaping error would leave the other ranks waiting for this one forever.
int run_point(const SweepPlan &plan, std::size_t n, const cli::ParsedArguments &args, int threads, int rank)
{
  const auto started = std::chrono::steady_clock::now();
  int rc = 1;
  double earlier = 0.0; // seconds spent on this point before (--resume)
  fs::path dir = plan.sweep_dir / ("p" + std::to_string(n));
  try
  {
    const PointSetup point = set_up_point(plan, n);
    dir = point.dir;
    fs::create_directories(point.dir);
    // A result of an earlier run must not stand for this one: the point says it is running
    // (and keeps saying so if it is stopped), with the time it had already spent when resumed.
    earlier = args.has("--resume") ? time_spent_before(point.dir) : 0.0;
    write_point_result(point.dir, seconds_cell(earlier), "running", rank, plan.spin_up);
    std::cout << "\n##### magbrush sweep: point " << n + 1 << "/" << plan.points.size() << ": " << point.label
              << " (" << (point.point_case.populations.empty() ? 0 : point.point_case.populations[0].count)
              << " beads) #####" << std::endl;
    std::vector<std::string> run_args = run_words(plan, plan.skip, point.overrides, args, threads);
    // A fork of the spin-up, unless it resumes its own checkpoint.
    const bool resumes_itself = args.has("--resume") && fs::exists(point.dir / "dem" / "checkpoint.bin");
    if (plan.spin_up && !resumes_itself)
    {
      const auto fork = fork_words(*plan.spin_up, point.point_case);
      run_args.insert(run_args.end(), fork.begin(), fork.end());
    }
    rc = run_pipeline(run_args);
  }
  catch (const std::exception &e)
  {
    std::cerr << "magbrush sweep: point " << n << " failed: " << e.what() << "\n";
    rc = 1;
  }
  const double run_time = earlier + std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  try
  {
    fs::create_directories(dir);
    write_point_result(dir, seconds_cell(run_time), rc == 0 ? "ok" : "failed", rank, plan.spin_up);
  }
  catch (const std::exception &e)
  {
    std::cerr << "magbrush sweep: cannot keep point " << n << "'s result: " << e.what() << "\n";
    rc = rc == 0 ? 1 : rc;
  }
  return rc;
}

// The spin-up every point forks from (sweep_spin_up.h): the case at the sweep's --set values to
// the fork, in its own folder, once; a spin-up that finished with the same case is reused, and
// one stopped before its end continues from its checkpoint with --resume.
int run_spin_up(const SweepPlan &plan, const cli::ParsedArguments &args, int threads)
{
  const SweepSpinUp &spin = *plan.spin_up;
  if (spin_up_done(spin))
  {
    std::cout << "magbrush sweep: the spin-up in " << spin.dir.string() << "/ (to "
              << spin.duration * 1e3 << " ms) is done: every point forks from it" << std::endl;
    return 0;
  }
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::string> overrides = plan.overrides;
  char duration[64];
  std::snprintf(duration, sizeof duration, "dem.duration=%.9gs", spin.duration);
  overrides.push_back(duration);
  overrides.push_back("dem.leg=true"); // the points average after its end
  overrides.push_back("output.directory=" + spin.dir.string());
  overrides.push_back(fields_override(plan, overrides));
  std::cout << "\n##### magbrush sweep: the spin-up, to " << spin.duration * 1e3 << " ms, into " << spin.dir.string()
            << "/ #####" << std::endl;
  fs::create_directories(spin.dir);
  const int rc = run_pipeline(run_words(plan, plan.skip + ",report", overrides, args, threads));
  if (rc != 0)
  {
    std::cerr << "magbrush sweep: the spin-up failed (exit " << rc << "): no point can fork from it\n";
    return rc;
  }
  record_spin_up(spin, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  return 0;
}

// sweep_mean.csv: the repeats of each point (neighbours in the run table, the seed varied
// last) as one row: the varied values without the seed, the number of repeats that ran, every
// key's mean with the standard error of the repeats' spread (common/study_repeats.h), the
// summed run time and whether every repeat ran.
std::string means_of_repeats_csv(const SweepPlan &plan, const std::vector<StudyPoint> &runs,
                                 const std::vector<std::string> &run_header, const std::vector<double> &run_first_x)
{
  const std::size_t varied = plan.vary.size(), seed_given = varied - 1, seed_si = 2 * varied - 1;
  auto without_seed = [&](const std::vector<std::string> &cells) {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < cells.size(); ++k)
      if (k != seed_given && k != seed_si)
        out.push_back(cells[k]);
    return out;
  };
  std::vector<StudyPoint> means;
  std::vector<double> first_x;
  for (std::size_t first = 0; first < runs.size(); first += plan.repeats)
  {
    StudyPoint mean;
    mean.label = "p" + std::to_string(first / plan.repeats);
    for (std::size_t k = 0; k + 1 < varied; ++k)
      mean.label += "_" + label_of(plan.vary[k].key, plan.vary[k].values[plan.points[first][k]]);
    mean.leading = without_seed(runs[first].leading);
    std::vector<std::vector<SummaryRow>> summaries;
    double run_time = 0.0;
    std::size_t ran = 0;
    for (std::size_t r = first; r < first + plan.repeats; ++r)
    {
      run_time += std::atof(runs[r].trailing[0].c_str());
      if (runs[r].trailing[1] != "ok")
        continue;
      summaries.push_back(runs[r].summary);
      ++ran;
    }
    mean.leading.push_back(std::to_string(ran));
    mean.summary = mean_of_repeats(summaries);
    char cell[64];
    std::snprintf(cell, sizeof cell, "%.1f", run_time);
    mean.trailing = {cell, ran == plan.repeats ? "ok" : std::to_string(plan.repeats - ran) + " of " +
                                                          std::to_string(plan.repeats) + " repeats failed"};
    means.push_back(mean);
    first_x.push_back(run_first_x[first]);
  }
  std::vector<std::string> header = without_seed(run_header);
  header.push_back("repeats");
  std::optional<MeasuredComparison> comparison;
  if (plan.measured)
    comparison = compare_with(*plan.measured, first_x, plan.tolerance);
  return study_table_csv("magbrush sweep of " + plan.case_path + ": the mean of " + std::to_string(plan.repeats) +
                             " repeats per point (dem.seed " + plan.vary.back().values.front() + " .. " +
                             plan.vary.back().values.back() + "), standard errors from their spread",
                         header, {"run_time_s", "status"}, means, comparison);
}

// The table, the profiles and the plots from every point's folder. Returns 1 when a point
// failed or has not run (its row says which), else 0.
int merge_points(const SweepPlan &plan)
{
  std::vector<StudyPoint> table;
  std::vector<double> first_x; // the first varied key's SI value per point (for --measured)
  std::ostringstream profiles;
  profiles << "# magbrush sweep profiles of " << plan.case_path << " (columns after 'point' as in nip_profile.csv)\n";
  bool profile_header = false;
  std::vector<std::string> failed, missing, unfinished;
  for (std::size_t n = 0; n < plan.points.size(); ++n)
  {
    const PointSetup point = set_up_point(plan, n);
    const auto [run_time_cell, status] = read_point_result(point.dir);
    if (status == "missing")
      missing.push_back(std::to_string(n) + " (" + point.label + ")");
    else if (status == "running")
      unfinished.push_back(std::to_string(n) + " (" + point.label + ")");
    else if (status != "ok")
      failed.push_back(std::to_string(n) + " (" + point.label + ")");
    // Gather the point's key numbers (whatever its measurements report) and profile.
    StudyPoint row;
    row.label = point.label;
    for (std::size_t k = 0; k < plan.vary.size(); ++k)
      row.leading.push_back(plan.vary[k].values[plan.points[n][k]]);
    char cell[64];
    for (std::size_t k = 0; k < plan.vary.size(); ++k)
    {
      const double x = si_value(plan.vary[k].key, plan.vary[k].values[plan.points[n][k]]);
      std::snprintf(cell, sizeof cell, "%.9g", x);
      row.leading.push_back(cell);
      if (k == 0)
        first_x.push_back(x);
    }
    const Case &c = point.point_case;
    const double d = c.populations.empty() ? 0.0 : c.populations[0].diameter_mean;
    row.leading.push_back(std::to_string(c.populations.empty() ? 0L : c.populations[0].count));
    std::snprintf(cell, sizeof cell, "%.4g", d * 1e6);
    row.leading.push_back(cell);
    row.summary = read_summary_csv((point.dir / "dem" / "summary.csv").string());
    // Kawamoto's contact density scales as 1/d²: density × d² is the size-free number (Fig. 24).
    for (const auto &r : std::vector<SummaryRow>(row.summary))
      if (r.key == "density_at_gap_centre_per_mm2")
        row.summary.push_back({"density_x_d2_at_gap_centre", r.value * (d * 1e3) * (d * 1e3),
                               std::numeric_limits<double>::quiet_NaN()});
    row.trailing = {run_time_cell, status};
    table.push_back(row);
    std::ifstream prof(point.dir / "dem" / "nip_profile.csv");
    std::string line;
    bool header = true;
    while (std::getline(prof, line))
    {
      if (line.empty() || line[0] == '#')
        continue;
      if (header)
      {
        header = false;
        if (!profile_header)
          profiles << "point," << line << "\n";
        profile_header = true;
        continue;
      }
      profiles << point.label << "," << line << "\n";
    }
  }
  std::vector<std::string> leading_header;
  for (const auto &v : plan.vary)
    leading_header.push_back(v.key);
  for (const auto &v : plan.vary)
    leading_header.push_back(si_header(v.key));
  leading_header.push_back("count");
  leading_header.push_back("diameter_um");
  std::optional<MeasuredComparison> comparison;
  if (plan.measured)
    comparison = compare_with(*plan.measured, first_x, plan.tolerance);
  const std::string summary = study_table_csv("magbrush sweep of " + plan.case_path, leading_header,
                                              {"run_time_s", "status"}, table, comparison);
  fs::create_directories(plan.sweep_dir);
  write_text_atomically((plan.sweep_dir / "sweep_summary.csv").string(), summary);
  if (plan.repeats > 1)
  {
    const std::string means = means_of_repeats_csv(plan, table, leading_header, first_x);
    write_text_atomically((plan.sweep_dir / "sweep_mean.csv").string(), means);
    std::cout << "\nmagbrush sweep: " << (plan.sweep_dir / "sweep_mean.csv").string() << "\n" << means;
  }
  write_text_atomically((plan.sweep_dir / "sweep_profiles.csv").string(), profiles.str());
  std::cout << "\nmagbrush sweep: " << (plan.sweep_dir / "sweep_summary.csv").string() << "\n" << summary;

  // The comparison plots (tools/plot_sweep.py).
  const std::string chosen = find_tool_script("plot_sweep.py");
  const char *env_python = std::getenv("MAGBRUSH_PYTHON");
  const std::string python = env_python ? env_python : (fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3");
  const std::vector<std::string> command = {python, chosen, "--dir", plan.sweep_dir.string()};
  const std::string failure = chosen.empty() ? "tools/plot_sweep.py not found; set MAGBRUSH_TOOLS to the tools folder"
                                              : run_program_failure(command);
  if (!failure.empty())
    std::cerr << "magbrush sweep: the comparison plots failed (" << failure << ": " << python << " " << chosen
              << " --dir " << plan.sweep_dir.string() << "); the CSV files are written\n";
  auto listed = [](const std::vector<std::string> &items) {
    std::string text;
    for (const auto &i : items)
      text += (text.empty() ? "" : ", ") + i;
    return text;
  };
  if (!missing.empty())
    std::cerr << "magbrush sweep: " << missing.size() << " of " << plan.points.size()
              << " points have not run (no " << point_result_name << " in their folders): " << listed(missing)
              << "; run them with --point INDEX, then merge again\n";
  if (!unfinished.empty())
    std::cerr << "magbrush sweep: " << unfinished.size() << " of " << plan.points.size()
              << " points have not finished (running, or stopped before their end): " << listed(unfinished)
              << "; --resume continues them from their checkpoints, then merge again\n";
  if (!failed.empty())
    std::cerr << "magbrush sweep: " << failed.size() << " of " << plan.points.size()
              << " points failed (their rows say so; see their logs in the point folders): " << listed(failed) << "\n";
  return missing.empty() && unfinished.empty() && failed.empty() ? 0 : 1;
}

// The sweep's own words as given, for the Slurm scripts: the case and any file by absolute
// path, without --emit (the scripts add --point or --merge).
std::vector<std::string> words_for_slurm(const cli::ParsedArguments &args)
{
  std::vector<std::string> words = {fs::absolute(executable_dir() + "/magbrush").lexically_normal().string(), "sweep",
                                    fs::absolute(args.positional(0)).lexically_normal().string()};
  for (const auto &given : args.given())
  {
    if (given.option->name == "--emit")
      continue;
    words.push_back(given.option->name);
    if (given.option->takes_value())
      words.push_back(given.option->name == "--measured" ? fs::absolute(given.value).lexically_normal().string()
                                                         : given.value);
  }
  return words;
}

int emit_slurm(const SweepPlan &plan, const cli::ParsedArguments &args)
{
  fs::create_directories(plan.sweep_dir);
  const fs::path folder = fs::absolute(plan.sweep_dir).lexically_normal();
  SlurmSweep job;
  job.job_name = "sweep_" + plan.name;
  job.points = plan.points.size();
  job.work_dir = fs::current_path().string();
  job.log_dir = folder.string();
  job.point_command = words_for_slurm(args);
  job.merge_command = job.point_command;
  job.merge_command.push_back("--merge");
  job.threads_given = args.has("--threads");
  const fs::path array_script = folder / (job.job_name + ".slurm");
  const fs::path merge_script = folder / (job.job_name + "_merge.slurm");
  write_text_atomically(array_script.string(), slurm_array_script(job, merge_script.string(), array_script.string()));
  write_text_atomically(merge_script.string(), slurm_merge_script(job));
  fs::permissions(array_script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  fs::permissions(merge_script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  std::cout << "magbrush sweep: " << plan.points.size() << " points as a Slurm job array (nothing run):\n  "
            << array_script.string() << "\n  " << merge_script.string() << "\nSubmit them with\n  jid=$(sbatch --parsable "
            << shell_quoted(array_script.string()) << ") && sbatch --dependency=afterok:$jid "
            << shell_quoted(merge_script.string()) << "\n";
  return 0;
}

// --point's value: an index of this sweep's points, or an error naming the range.
std::size_t point_index(const cli::ParsedArguments &args, const SweepPlan &plan)
{
  const std::string text = args.value("--point");
  const std::size_t n = plan.points.size();
  char *end = nullptr;
  const long long i = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || i < 0 || static_cast<unsigned long long>(i) >= n)
    throw cli::UsageError("--point expects a point of this sweep, 0 to " + std::to_string(n - 1) + " (" +
                          std::to_string(n) + " points), found '" + text + "'");
  return static_cast<std::size_t>(i);
}

int sweep(const cli::ParsedArguments &args)
{
  const bool one_point = args.has("--point"), merge_only = args.has("--merge"), emit = args.has("--emit");
  if (one_point + merge_only + emit > 1)
    throw cli::UsageError("--point, --merge and --emit are steps of their own: give one of them");
  if ((one_point || merge_only || emit) && launched_by_mpi())
    throw cli::UsageError(std::string(one_point ? "--point" : merge_only ? "--merge" : "--emit") +
                          " is one process's step: run it without mpirun (mpirun -np K magbrush sweep ... "
                          "deals the points to the ranks by itself)");
  const SweepPlan plan = plan_sweep(args);
  if (emit)
    return emit_slurm(plan, args);
  if (merge_only)
    return merge_points(plan);
  fs::create_directories(plan.sweep_dir);
  if (plan.spin_up)
    std::cout << "magbrush sweep: every point forks from a spin-up to " << plan.spin_up->duration * 1e3
              << " ms and averages from " << plan.spin_up->averages_from() * 1e3 << " ms on.\n"
              << settle_estimate(plan.base);
  if (one_point)
  {
    // A task of a job array: the first task to find no spin-up builds it (run one task, or a
    // sweep with --spin-up and --point 0, before the others).
    if (plan.spin_up && run_spin_up(plan, args, 0) != 0)
      return 1;
    return run_point(plan, point_index(args, plan), args, 0, 0);
  }

  // Every point, dealt to the ranks of an MPI job (one rank of one without mpirun).
  const SweepRanks ranks;
  const int threads = ranks.threads_per_rank();
  if (plan.spin_up)
  {
    // Rank 0 builds it (with the node's cores when alone); the others wait for it.
    const int spin_failed = ranks.rank() == 0 ? (run_spin_up(plan, args, ranks.distributed() ? 0 : threads) != 0) : 0;
    if (ranks.sum_over_ranks(spin_failed) > 0)
      return 1;
  }
  if (ranks.rank() == 0)
    std::cout << "magbrush sweep: " << plan.points.size() << " points into " << plan.sweep_dir.string() << "/\n";
  if (ranks.distributed())
  {
    std::cout << "magbrush sweep: rank " << ranks.rank() << " of " << ranks.size() << " runs points";
    const char *separator = " ";
    for (std::size_t n = 0; n < plan.points.size(); ++n)
      if (ranks.owns(n))
      {
        std::cout << separator << n;
        separator = ", ";
      }
    std::cout << " with " << (args.has("--threads") ? args.value("--threads") : std::to_string(threads))
              << " DEM threads" << std::endl;
  }
  int failures = 0;
  for (std::size_t n = 0; n < plan.points.size(); ++n)
    if (ranks.owns(n) && run_point(plan, n, args, threads, ranks.rank()) != 0)
      ++failures;
  // Every rank has finished its points here: rank 0 alone writes the table, once.
  const int failed_anywhere = ranks.sum_over_ranks(failures);
  if (ranks.rank() != 0)
    return failed_anywhere > 0 ? 1 : 0;
  return merge_points(plan);
}

int run_sweep(const std::vector<std::string> &args)
{
  return cli::run_command(sweep_command_line(), {args.begin() + 1, args.end()}, sweep);
}

const bool registered = register_subcommand(
    {"sweep", "the pipeline over a parameter sweep, with the nip profiles compared (Fig. 22-27)", run_sweep,
     sweep_command_line, 95});

} // namespace
} // namespace magbrush
