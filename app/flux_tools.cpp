// What `magbrush flux` and `magbrush design` share (see flux_tools.h).
#include "app/flux_tools.h"

#include "app/subcommand.h"
#include "calibration/flux_scan.h"
#include "common/child_process.h"
#include "case/case_hash.h"
#include "fields/field_files.h"
#include "fields/field_grid.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace fs = std::filesystem;
namespace {
constexpr double to_deg = 180.0 / M_PI;
} // namespace

std::string fixed(double v, int digits)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string scientific(double v)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1e", v);
  return buf;
}

double probe_radius_of(const Case &c)
{
  if (!c.roller)
    throw std::invalid_argument("the case has no roller; magbrush flux needs roller.poles");
  double r = c.field.probe_radius;
  if (r == 0.0)
  {
    if (!c.sleeve)
      throw std::invalid_argument("field.probe_radius is 0 (= the sleeve radius) but the case has "
                                  "no sleeve; set field.probe_radius");
    r = c.sleeve->radius;
  }
  if (r < c.roller->magnet_radius)
    throw std::invalid_argument("the probe radius " + fixed(r * 1e3, 3) +
                                " mm lies inside the magnet (outer radius " +
                                fixed(c.roller->magnet_radius * 1e3, 3) +
                                " mm); a gaussmeter scans outside it: set field.probe_radius to a "
                                "radius ≥ the magnet radius (0 = the sleeve radius)");
  return r;
}

// The FEM profile at this radius, if magbrush-field wrote one for the case as it is now:
// the profile's "# ... radius R mm." line must match the probe radius, and the stored magnetic
// field it came from (<case>_magnetic.h5) must carry the case's current field hash.
std::string fem_profile_path(const Case &c, double probe_radius, std::string &why_not)
{
  const std::string path = field::field_file(c, "profile_probe.csv");
  std::ifstream in(path);
  if (!in)
  {
    why_not = "no finite-element profile " + path + " (run `magbrush field` first to compare the FEM)";
    return "";
  }
  std::string line;
  while (std::getline(in, line) && !line.empty() && line[0] == '#')
  {
    const auto at = line.find("radius ");
    if (at == std::string::npos)
      continue;
    const double r = std::atof(line.c_str() + at + 7) * 1e-3;
    if (std::abs(r - probe_radius) > 1e-7) // the file prints 6 significant digits
    {
      why_not = path + " is at radius " + fixed(r * 1e3, 3) + " mm, not the probe radius " +
                fixed(probe_radius * 1e3, 3) + " mm";
      return "";
    }
    break;
  }
  const std::string grid = field::magnetic_grid_path(c);
  if (fs::exists(grid))
  {
    try
    {
      const GridFileInfo info = read_grid_info(grid);
      const std::string difference =
          provenance_difference(info, case_provenance(c, FieldKind::magnetic).case_inputs);
      if (!difference.empty())
      {
        why_not = path + " is stale: " + difference;
        return "";
      }
    }
    catch (const std::exception &e)
    {
      why_not = "cannot check that " + path + " belongs to this case (" + e.what() + ")";
      return "";
    }
  }
  return path;
}

ComputedProfile computed_at(const std::vector<double> &angles, const MultipoleRing &ring,
                            double probe_radius, const std::string &fem_path)
{
  ComputedProfile p;
  if (!fem_path.empty())
  {
    ScanReadOptions o;
    o.min_points = 16;
    const FluxScan fem = read_flux_scan(fem_path, o);
    p.Bn = interpolate_periodic(fem.angle, fem.Bn, angles);
    p.Bt = fem.has_tangential() ? interpolate_periodic(fem.angle, fem.Bt, angles)
                                : std::vector<double>(angles.size(), 0.0);
    p.source = "finite-element field (" + fem_path + ")";
    return p;
  }
  ring.profile(probe_radius, angles, p.Bn, p.Bt);
  p.source = "exact multipole ring (" + std::to_string(ring.harmonic_count()) + " harmonics)";
  return p;
}

std::string run_magnetic_field_solver(const std::string &case_file, const std::string &log,
                                      const std::vector<std::string> &overrides)
{
  const fs::path field_exe = fs::path(executable_dir()) / "magbrush-field";
  if (!fs::exists(field_exe))
    return field_exe.string() + " is not built (build the magbrush-field target)";
  ChildOutput to_log;
  to_log.stdout_path = log;
  to_log.stderr_to_stdout = true;
  try
  {
    std::vector<std::string> words = {field_exe.string(), case_file, "--only", "magnetic", "--no-vtu"};
    for (const auto &o : overrides)
    {
      words.push_back("--set");
      words.push_back(o);
    }
    const int status = run_program(words, to_log);
    if (status != 0)
      return "magbrush-field exited with status " + std::to_string(status) + " (see " + log + ")";
  }
  catch (const ChildProcessError &e)
  {
    return e.what();
  }
  return "";
}

void run_plot_script(const std::string &script_name, const std::vector<std::string> &script_arguments,
                     const std::string &png)
{
  const std::string script = find_tool_script(script_name);
  if (script.empty())
  {
    std::cout << "warning: tools/" << script_name << " not found (set MAGBRUSH_TOOLS to the tools "
                 "directory); no plot written\n";
    return;
  }
  std::vector<std::string> arguments = {script};
  arguments.insert(arguments.end(), script_arguments.begin(), script_arguments.end());
  // The first interpreter that has matplotlib: $MAGBRUSH_PYTHON, python3 on the PATH, then the
  // system's (a pyenv or venv python3 on the PATH often lacks the Debian matplotlib).
  // $MAGBRUSH_PYTHON, when set, is the only one tried.
  std::vector<std::string> interpreters;
  if (const char *env = std::getenv("MAGBRUSH_PYTHON"))
    interpreters.push_back(env);
  else
  {
    interpreters.push_back("python3");
    if (fs::exists("/usr/bin/python3"))
      interpreters.push_back("/usr/bin/python3");
  }
  // The script exits with 3 when matplotlib is missing; 127 stands for "could not start".
  int status = 127;
  ChildOutput quiet;
  quiet.stderr_path = "/dev/null";
  for (const auto &python : interpreters)
  {
    std::vector<std::string> command = {python};
    command.insert(command.end(), arguments.begin(), arguments.end());
    try
    {
      status = run_program(command, quiet);
    }
    catch (const ChildProcessError &)
    {
      status = 127;
    }
    if (status != 3 && status != 127)
      break;
  }
  if (status == 0)
    std::cout << "  plot        " << png << "\n";
  else if (status == 127)
    std::cout << "warning: python3 not found; no plot written (install python3 and "
                 "python3-matplotlib)\n";
  else if (status == 3)
    std::cout << "warning: matplotlib is missing; no plot written (install python3-matplotlib)\n";
  else
    std::cout << "warning: the plot script failed (status " << status << "); no plot written\n";
}

void apply_override(YAML::Node root, const std::string &override_text)
{
  const auto eq = override_text.find('=');
  if (eq == std::string::npos)
    return;
  std::vector<std::string> keys;
  std::stringstream ks(override_text.substr(0, eq));
  for (std::string k; std::getline(ks, k, '.');)
    keys.push_back(k);
  YAML::Node node = root;
  for (size_t i = 0; i < keys.size(); ++i)
  {
    std::string key = keys[i];
    const bool last = i + 1 == keys.size();
    if (node.IsSequence())
    {
      YAML::Node next;
      if (key.size() > 2 && key.front() == '[' && key.back() == ']')
      {
        const size_t index = std::stoul(key.substr(1, key.size() - 2));
        if (index < node.size())
          next.reset(node[index]);
      }
      else
        for (const auto &element : node)
          if (element.IsMap() && element["name"] && element["name"].as<std::string>() == key)
            next.reset(element);
      // Not addressable, or a whole list element: leave the file's text (the loaded case
      // itself had the override applied by the parser).
      if (!next.IsDefined() || next.IsNull() || last)
        return;
      node.reset(next);
      continue;
    }
    if (last)
    {
      node[key] = override_text.substr(eq + 1);
      return;
    }
    if (!node[key])
      node[key] = YAML::Node(YAML::NodeType::Map);
    YAML::Node next = node[key];
    node.reset(next);
  }
}

YAML::Node poles_yaml(const std::vector<Pole> &poles)
{
  YAML::Node list(YAML::NodeType::Sequence);
  for (const auto &p : poles)
  {
    YAML::Node n(YAML::NodeType::Map);
    n.SetStyle(YAML::EmitterStyle::Flow);
    n["name"] = p.name;
    // In [0, 360) also after rounding (359.99996 would print as 360.0000, out of range).
    double angle_deg = std::round(p.angle * to_deg * 1e4) / 1e4;
    if (angle_deg < 0.0)
      angle_deg += 360.0;
    if (angle_deg >= 360.0)
      angle_deg -= 360.0;
    n["angle"] = fixed(angle_deg, 4) + " deg";
    n["strength"] = fixed(p.strength * 1e-3, 3) + " kA/m";
    n["shape_factor"] = fixed(p.shape_factor, 4) + " rad^-2";
    list.push_back(n);
  }
  return list;
}

} // namespace magbrush
