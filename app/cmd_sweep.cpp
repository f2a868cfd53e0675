// `magbrush sweep CASE --vary key=v1,v2,... [--vary ...]`: the pipeline once per point of a
// parameter sweep, each point in its own output folder, then every point's key numbers in one
// table and plot: Kawamoto's nip studies (Fig. 22–27: carrier diameter, supplied layer,
// development gap), Kweon's TMA against the bias and DMA against the blade gap.
//
//   points = the Cartesian product of the --vary lists → for each: its overrides (a carrier
//   diameter also rescales the bead count so that the supplied volume — the layer — stays the
//   same) → `magbrush run` with output.directory and field.output_dir inside the point's
//   folder, timed → gather every point's dem/summary.csv (whatever its measurements report,
//   with standard errors and the steady-state verdict) into sweep_summary.csv
//   (common/study_table.h), with a measured series compared when given, and the nip profiles
//   into sweep_profiles.csv → tools/plot_sweep.py draws each key against the varied value
//   (error bars, the physical bound, the measured points) and the profiles side by side.
#include "app/run_pipeline.h"
#include "app/subcommand.h"

#include "coupling/case_parser.h"
#include "coupling/case_schema.h"
#include "coupling/units.h"
#include "common/atomic_file.h"
#include "common/child_process.h"
#include "common/study_table.h"

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
              "                      [--name NAME] [--no-keep-layer] [--skip STAGE[,STAGE]] [options of the stages]";
    s.description = R"(Runs the pipeline (check, field, dem, report; the Gmsh meshes are not needed per point) once
for every combination of the --vary values, each point in
<output.directory>/sweep_<NAME>/<point>/ (its own fields/, dem/, report/), then compares the
nip profiles of all points:
  sweep_summary.csv    one row per point: the varied values (as given and in SI), the bead
                       count, every key number the point's measurements report (dem/summary.csv:
                       e.g. slip at the gap centre, normal force per length, TMA, DMA) with its
                       standard error, steady_state (1: every tested mean drifts < 2 %), the
                       run time of the point, and with --measured the measured value, the
                       relative error and a within-tolerance flag
  sweep_profiles.csv   every point's profile along the nip (long format), for nip scenes
  sweep_<key>.png      each key with a standard error against the (first) varied value, with
                       its physical bound (<key>_bound) and the measured points
  sweep_slip.png, sweep_pressure.png, sweep_density.png   (Kawamoto Fig. 17-19, 22-27)
Values carry units as in the case file (--vary populations.carrier.diameter=42um,50um,60um).
Varying a population's diameter also scales its count by (d0/d)^3 and its diameter_std by
d/d0, so that the supplied carrier volume (the layer) stays the same, as in the paper's
42/50/60 um comparison, and a fixed dem.time_step by d/d0 (the stable step is proportional to
the bead size); --no-keep-layer switches that off.
The options of the stages (named in brackets) go to the stages that declare them, at every point.
)";
    s.positionals = {{"CASE", "the case file"}};
    s.options = {{"--vary", {}, "key=v1,v2", "the values of one key to run (repeatable: every combination)", true},
                 cli::set_option(),
                 {"--name", {}, "NAME", "the sweep's folder is sweep_NAME (default: the varied keys' names)"},
                 {"--no-keep-layer", {}, "", "do not rescale the count, diameter_std and time step with a diameter"},
                 {"--skip", {}, "STAGE[,STAGE]", "stages not run at each point (default: mesh)"},
                 {"--measured", {}, "FILE", "a measured series to compare: CSV with the varied key and a summary key "
                                            "as columns (e.g. electric.bias,tma_kg_per_m2; values in SI or with units)"},
                 {"--tolerance", {}, "FRACTION", "relative error counted as agreement with --measured (default 0.1)"}};
    const auto of_stages = stage_options();
    s.options.insert(s.options.end(), of_stages.begin(), of_stages.end());
    s.epilog = R"(Examples (Fig. 22-27):
  magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.diameter=42um,50um,60um
  magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.count=9000,12300,15000
  magbrush sweep cases/kawamoto_nip.yaml --vary drum.gap=0.3mm,0.4mm,0.5mm
)";
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

// The case key's declaration for an override path: "populations.carrier.diameter" is declared
// as "populations[].diameter", "materials.toner.hamaker" as "materials.*.hamaker".
const KeySpec *spec_of_path(const std::string &path)
{
  if (const KeySpec *s = find_key_spec(path))
    return s;
  const auto first = path.find('.'), second = path.find('.', first + 1);
  if (first == std::string::npos || second == std::string::npos)
    return nullptr;
  for (const char *wild : {"[]", ".*"})
  {
    const std::string head = path.substr(0, first);
    const std::string pattern = std::string(wild) == "[]" ? head + "[]" + path.substr(second)
                                                          : head + ".*" + path.substr(second);
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
    return parse_quantity(text, spec ? spec->dimension : Dimension::dimensionless);
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

int sweep(const cli::ParsedArguments &args)
{
  const std::string case_path = args.positional(0), skip = args.value("--skip", "mesh");
  std::string name = args.value("--name");
  const std::vector<std::string> overrides = args.values("--set");
  const bool keep_layer = !args.has("--no-keep-layer");
  std::vector<Vary> vary;
  for (const auto &v : args.values("--vary"))
    vary.push_back(parse_vary(v));
  if (vary.empty())
    throw cli::UsageError("nothing to vary: give --vary key=v1,v2,...");
  std::optional<MeasuredSeries> measured;
  const double tolerance = std::atof(args.value("--tolerance", "0.1").c_str());
  if (args.has("--measured") && vary.size() > 1)
    throw cli::UsageError("--measured compares along one varied key; this sweep varies " + std::to_string(vary.size()));
  if (!(tolerance > 0.0))
    throw cli::UsageError("--tolerance expects a positive fraction (0.1 = 10 %), found '" +
                          args.value("--tolerance", "") + "'");
  if (args.has("--measured"))
    measured = read_measured(args.value("--measured"), vary[0].key);
  const Case base = load_case(case_path, overrides);
  if (name.empty())
    for (const auto &v : vary)
      name += (name.empty() ? "" : "_") + v.key.substr(v.key.find_last_of('.') + 1);
  const fs::path sweep_dir = fs::path(base.output.directory) / ("sweep_" + name);
  fs::create_directories(sweep_dir);

  // Every combination (the last --vary runs fastest).
  std::vector<std::vector<std::size_t>> points(1);
  for (const auto &v : vary)
  {
    std::vector<std::vector<std::size_t>> next;
    for (const auto &p : points)
      for (std::size_t k = 0; k < v.values.size(); ++k)
      {
        next.push_back(p);
        next.back().push_back(k);
      }
    points = next;
  }
  std::cout << "magbrush sweep: " << points.size() << " points into " << sweep_dir.string() << "/\n";

  std::vector<StudyPoint> table;
  std::vector<double> first_x; // the first varied key's SI value per point (for --measured)
  std::ostringstream profiles;
  profiles << "# magbrush sweep profiles of " << case_path << " (columns after 'point' as in nip_profile.csv)\n";
  bool profile_header = false;
  int failures = 0;
  for (std::size_t n = 0; n < points.size(); ++n)
  {
    std::vector<std::string> point_overrides = overrides;
    std::string label = "p" + std::to_string(n);
    for (std::size_t k = 0; k < vary.size(); ++k)
    {
      const std::string &key = vary[k].key, &val = vary[k].values[points[n][k]];
      point_overrides.push_back(key + "=" + val);
      label += "_" + label_of(key, val);
    }
    // Keep the supplied carrier volume when a diameter changes: count × (d0/d)³, std × d/d0.
    Case point_case = load_case(case_path, point_overrides);
    for (std::size_t k = 0; k < vary.size() && keep_layer; ++k)
    {
      std::string selector;
      const Population *p0 = population_of(base, vary[k].key, selector);
      if (!p0 || vary[k].key.substr(vary[k].key.find_last_of('.') + 1) != "diameter" || p0->count <= 0)
        continue;
      const Population *p1 = population_of(point_case, vary[k].key, selector);
      const double ratio = p0->diameter_mean / p1->diameter_mean;
      const long count = std::lround(static_cast<double>(p0->count) * ratio * ratio * ratio);
      point_overrides.push_back("populations." + selector + ".count=" + std::to_string(count));
      char std_text[64];
      std::snprintf(std_text, sizeof std_text, "%.9g", p0->diameter_std / ratio);
      point_overrides.push_back("populations." + selector + ".diameter_std=" + std_text);
      // The stable step scales with the bead size (Hertz contact time ∝ d): a case that fixes
      // its step keeps the same fraction of the limit.
      if (base.dem.time_step > 0.0)
      {
        std::snprintf(std_text, sizeof std_text, "%.9g", base.dem.time_step / ratio);
        point_overrides.push_back("dem.time_step=" + std::string(std_text));
      }
    }
    const fs::path point_dir = sweep_dir / label;
    point_overrides.push_back("output.directory=" + point_dir.string());
    point_overrides.push_back("field.output_dir=" + (point_dir / "fields").string());
    point_case = load_case(case_path, point_overrides);
    std::cout << "\n##### magbrush sweep: point " << n + 1 << "/" << points.size() << ": " << label << " ("
              << (point_case.populations.empty() ? 0 : point_case.populations[0].count) << " beads) #####"
              << std::endl;
    std::vector<std::string> run_args = {"run", case_path, "--skip", skip};
    for (const auto &o : point_overrides)
    {
      run_args.push_back("--set");
      run_args.push_back(o);
    }
    const auto stage_words = options_for_the_stages(args);
    run_args.insert(run_args.end(), stage_words.begin(), stage_words.end());
    const auto started = std::chrono::steady_clock::now();
    const int rc = run_pipeline(run_args);
    const double run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (rc != 0)
      ++failures;
    // Gather the point's key numbers (whatever its measurements report) and profile.
    StudyPoint row;
    row.label = label;
    for (std::size_t k = 0; k < vary.size(); ++k)
      row.leading.push_back(vary[k].values[points[n][k]]);
    char cell[64];
    for (std::size_t k = 0; k < vary.size(); ++k)
    {
      const double x = si_value(vary[k].key, vary[k].values[points[n][k]]);
      std::snprintf(cell, sizeof cell, "%.9g", x);
      row.leading.push_back(cell);
      if (k == 0)
        first_x.push_back(x);
    }
    const double d = point_case.populations.empty() ? 0.0 : point_case.populations[0].diameter_mean;
    row.leading.push_back(std::to_string(point_case.populations.empty() ? 0L : point_case.populations[0].count));
    std::snprintf(cell, sizeof cell, "%.4g", d * 1e6);
    row.leading.push_back(cell);
    row.summary = read_summary_csv((point_dir / "dem" / "summary.csv").string());
    // Kawamoto's contact density scales as 1/d²: density × d² is the size-free number (Fig. 24).
    for (const auto &r : std::vector<SummaryRow>(row.summary))
      if (r.key == "density_at_gap_centre_per_mm2")
        row.summary.push_back({"density_x_d2_at_gap_centre", r.value * (d * 1e3) * (d * 1e3),
                               std::numeric_limits<double>::quiet_NaN()});
    std::snprintf(cell, sizeof cell, "%.1f", run_time);
    row.trailing = {cell, rc == 0 ? "ok" : "failed"};
    table.push_back(row);
    std::ifstream prof(point_dir / "dem" / "nip_profile.csv");
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
      profiles << label << "," << line << "\n";
    }
  }
  std::vector<std::string> leading_header;
  for (const auto &v : vary)
    leading_header.push_back(v.key);
  for (const auto &v : vary)
    leading_header.push_back(si_header(v.key));
  leading_header.push_back("count");
  leading_header.push_back("diameter_um");
  std::optional<MeasuredComparison> comparison;
  if (measured)
    comparison = compare_with(*measured, first_x, tolerance);
  const std::string summary = study_table_csv("magbrush sweep of " + case_path, leading_header,
                                              {"run_time_s", "status"}, table, comparison);
  write_text_atomically((sweep_dir / "sweep_summary.csv").string(), summary);
  write_text_atomically((sweep_dir / "sweep_profiles.csv").string(), profiles.str());
  std::cout << "\nmagbrush sweep: " << (sweep_dir / "sweep_summary.csv").string() << "\n" << summary;

  // The comparison plots (tools/plot_sweep.py).
  const std::string chosen = find_tool_script("plot_sweep.py");
  const char *env_python = std::getenv("MAGBRUSH_PYTHON");
  const std::string python = env_python ? env_python : (fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3");
  const std::vector<std::string> command = {python, chosen, "--dir", sweep_dir.string()};
  std::string failure = chosen.empty() ? "tools/plot_sweep.py not found; set MAGBRUSH_TOOLS to the tools folder" : "";
  try
  {
    if (!chosen.empty())
      if (const int status = run_program(command); status != 0)
        failure = "exit " + std::to_string(status);
  }
  catch (const ChildProcessError &e)
  {
    failure = e.what();
  }
  if (!failure.empty())
    std::cerr << "magbrush sweep: the comparison plots failed (" << failure << ": " << python << " " << chosen
              << " --dir " << sweep_dir.string() << "); the CSV files are written\n";
  if (failures > 0)
  {
    std::cerr << "magbrush sweep: " << failures << " of " << points.size()
              << " points failed (their rows say so; see their logs in the point folders)\n";
    return 1;
  }
  return 0;
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
