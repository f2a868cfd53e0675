// `magbrush sweep CASE --vary key=v1,v2,... [--vary ...]`: the pipeline once per point of a
// parameter sweep, each point in its own output folder, then the nip profiles of all points
// side by side (Kawamoto Fig. 22–27: carrier diameter, supplied layer, development gap).
//
//   points = the Cartesian product of the --vary lists → for each: its overrides (a carrier
//   diameter also rescales the bead count so that the supplied volume — the layer — stays the
//   same) → `magbrush run` with output.directory and field.output_dir inside the point's
//   folder → gather nip_summary.csv and nip_profile.csv of every point into
//   sweep_summary.csv / sweep_profiles.csv → tools/plot_sweep.py draws the comparison.
#include "app/run_pipeline.h"
#include "app/subcommand.h"

#include "coupling/case_parser.h"
#include "common/atomic_file.h"
#include "common/child_process.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
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
  sweep_summary.csv    one row per point: the varied values, the bead count, and the key
                       numbers (slip at the gap centre, peak and centre normal pressure,
                       tangential/normal, touching density, density x d^2, force per length)
  sweep_profiles.csv   every point's profile along the nip (long format)
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
                 {"--skip", {}, "STAGE[,STAGE]", "stages not run at each point (default: mesh)"}};
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

std::map<std::string, std::string> read_summary(const fs::path &path)
{
  std::map<std::string, std::string> values;
  std::ifstream in(path);
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
      values[cells[0]] = cells[1];
  }
  return values;
}

// "key=v1,v2,..." of one --vary.
Vary parse_vary(const std::string &v)
{
  const auto eq = v.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 >= v.size())
    throw cli::UsageError("--vary expects key=v1,v2,... (e.g. --vary drum.gap=0.3mm,0.4mm), found '" + v + "'");
  return {v.substr(0, eq), split(v.substr(eq + 1), ',')};
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

  std::ostringstream summary, profiles;
  summary << "# magbrush sweep of " << case_path << "\npoint";
  for (const auto &v : vary)
    summary << "," << v.key;
  summary << ",count,diameter_um,slip_at_gap_centre_m_s,relative_surface_speed_m_s,peak_normal_pressure_Pa,"
             "normal_pressure_at_gap_centre_Pa,tangential_over_normal,density_at_gap_centre_per_mm2,"
             "density_x_d2_at_gap_centre,normal_force_per_length_N_m,touching_beads,status\n";
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
    const int rc = run_pipeline(run_args);
    if (rc != 0)
      ++failures;
    // Gather the point's key numbers and profile.
    const auto s = read_summary(point_dir / "dem" / "nip_summary.csv");
    auto get = [&](const char *key) { return s.count(key) ? s.at(key) : std::string("nan"); };
    const double d = point_case.populations.empty() ? 0.0 : point_case.populations[0].diameter_mean;
    const double density = std::atof(get("density_at_gap_centre").c_str());
    summary << label;
    for (std::size_t k = 0; k < vary.size(); ++k)
      summary << "," << vary[k].values[points[n][k]];
    char row[512];
    std::snprintf(row, sizeof row, ",%ld,%.4g,%s,%s,%s,%s,%s,%s,%.6g,%s,%s,%s\n",
                  point_case.populations.empty() ? 0L : point_case.populations[0].count, d * 1e6,
                  get("slip_at_gap_centre").c_str(), get("relative_surface_speed").c_str(),
                  get("peak_normal_pressure").c_str(), get("normal_pressure_at_gap_centre").c_str(),
                  get("tangential_over_normal").c_str(), get("density_at_gap_centre").c_str(),
                  density * (d * 1e3) * (d * 1e3), get("normal_force_per_length").c_str(),
                  get("touching_beads").c_str(), rc == 0 ? "ok" : "failed");
    summary << row;
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
  write_text_atomically((sweep_dir / "sweep_summary.csv").string(), summary.str());
  write_text_atomically((sweep_dir / "sweep_profiles.csv").string(), profiles.str());
  std::cout << "\nmagbrush sweep: " << (sweep_dir / "sweep_summary.csv").string() << "\n" << summary.str();

  // The comparison plots (tools/plot_sweep.py, next to the sources of this build).
  const fs::path script = fs::path(__FILE__).parent_path().parent_path() / "tools" / "plot_sweep.py";
  const char *env_tools = std::getenv("MAGBRUSH_TOOLS");
  const fs::path chosen = env_tools ? fs::path(env_tools) / "plot_sweep.py" : script;
  const char *env_python = std::getenv("MAGBRUSH_PYTHON");
  const std::string python = env_python ? env_python : (fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3");
  const std::vector<std::string> command = {python, chosen.string(), "--dir", sweep_dir.string()};
  std::string failure;
  try
  {
    if (const int status = run_program(command); status != 0)
      failure = "exit " + std::to_string(status);
  }
  catch (const ChildProcessError &e)
  {
    failure = e.what();
  }
  if (!failure.empty())
    std::cerr << "magbrush sweep: the comparison plots failed (" << failure << ": " << python << " " << chosen.string()
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
