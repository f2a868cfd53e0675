// `magbrush sweep CASE --vary key=v1,v2,... [--vary ...]`: the pipeline once per point of a
// parameter sweep, each point in its own output folder, then the nip profiles of all points
// side by side (Kawamoto Fig. 22–27: carrier diameter, supplied layer, development gap).
//
//   points = the Cartesian product of the --vary lists → for each: its overrides (a carrier
//   diameter also rescales the bead count so that the supplied volume — the layer — stays the
//   same) → `magbrush run` with output.directory and field.output_dir inside the point's
//   folder → gather nip_summary.csv and nip_profile.csv of every point into
//   sweep_summary.csv / sweep_profiles.csv → tools/plot_sweep.py draws the comparison.
#include "run_pipeline.h"
#include "subcommand.h"

#include "case_parser.h"

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
#include <sys/wait.h>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

const char *sweep_help =
    R"(Usage: magbrush sweep CASE --vary key=v1,v2[,...] [--vary key=...] [--set key=value ...]
                      [--name NAME] [--no-keep-layer] [--skip STAGE[,STAGE]]

Runs the pipeline (check, field, dem, report; the Gmsh meshes are not needed per point) once
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
Examples (Fig. 22-27):
  magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.diameter=42um,50um,60um
  magbrush sweep cases/kawamoto_nip.yaml --vary populations.carrier.count=9000,12300,15000
  magbrush sweep cases/kawamoto_nip.yaml --vary drum.gap=0.3mm,0.4mm,0.5mm
)";

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

void write_atomically(const fs::path &path, const std::string &text)
{
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream o(tmp);
    o << text;
  }
  fs::rename(tmp, path);
}

std::string quoted(const std::string &s)
{
  std::string q = "'";
  for (char ch : s)
    q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

int run_sweep(const std::vector<std::string> &args)
{
  std::string case_path, name, skip = "mesh";
  std::vector<std::string> overrides;
  std::vector<Vary> vary;
  bool keep_layer = true;
  for (std::size_t i = 1; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size())
        throw std::invalid_argument(a + " needs a value (see magbrush sweep --help)");
      return args[++i];
    };
    if (a == "--help" || a == "-h")
    {
      std::cout << sweep_help;
      return 0;
    }
    else if (a == "--vary")
    {
      const std::string v = value();
      const auto eq = v.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 >= v.size())
        throw std::invalid_argument("--vary expects key=v1,v2,... (e.g. --vary drum.gap=0.3mm,0.4mm), found '" + v + "'");
      vary.push_back({v.substr(0, eq), split(v.substr(eq + 1), ',')});
    }
    else if (a == "--set")
      overrides.push_back(value());
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (a == "--name")
      name = value();
    else if (a == "--skip")
      skip = value();
    else if (a == "--no-keep-layer")
      keep_layer = false;
    else if (!a.empty() && a[0] == '-')
      throw std::invalid_argument("unknown option '" + a + "'");
    else if (case_path.empty())
      case_path = a;
    else
      throw std::invalid_argument("expected one case file, found a second: '" + a + "'");
  }
  if (case_path.empty() || vary.empty())
  {
    std::cerr << sweep_help;
    return 2;
  }
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
  write_atomically(sweep_dir / "sweep_summary.csv", summary.str());
  write_atomically(sweep_dir / "sweep_profiles.csv", profiles.str());
  std::cout << "\nmagbrush sweep: " << (sweep_dir / "sweep_summary.csv").string() << "\n" << summary.str();

  // The comparison plots (tools/plot_sweep.py, next to the sources of this build).
  const fs::path script = fs::path(__FILE__).parent_path().parent_path() / "tools" / "plot_sweep.py";
  const char *env_tools = std::getenv("MAGBRUSH_TOOLS");
  const fs::path chosen = env_tools ? fs::path(env_tools) / "plot_sweep.py" : script;
  const char *env_python = std::getenv("MAGBRUSH_PYTHON");
  const std::string python = env_python ? env_python : (fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3");
  const std::string cmd = quoted(python) + " " + quoted(chosen.string()) + " --dir " + quoted(sweep_dir.string());
  const int raw = std::system(cmd.c_str());
  if (raw != 0)
    std::cerr << "magbrush sweep: the comparison plots failed (" << cmd << "); the CSV files are written\n";
  if (failures > 0)
  {
    std::cerr << "magbrush sweep: " << failures << " of " << points.size()
              << " points failed (their rows say so; see their logs in the point folders)\n";
    return 1;
  }
  return 0;
}

int sweep_main(const std::vector<std::string> &args)
{
  try
  {
    return run_sweep(args);
  }
  catch (const std::invalid_argument &e)
  {
    std::cerr << "magbrush sweep: " << e.what() << "\n";
    return 2;
  }
}

const bool registered = register_subcommand(
    {"sweep", "the pipeline over a parameter sweep, with the nip profiles compared (Fig. 22-27)", sweep_main, 95});

} // namespace
} // namespace magbrush
