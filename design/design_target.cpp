// Reading design targets and constraints (see design_target.h).
#include "design/design_target.h"

#include "case/units.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace {

constexpr double two_pi = 2.0 * M_PI;

std::string lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// A quantity from a YAML scalar, the key named in the error.
double quantity(const YAML::Node &node, Dimension d, const std::string &where)
{
  try
  {
    return parse_quantity(node.as<std::string>(), d);
  }
  catch (const std::exception &e)
  {
    throw std::invalid_argument(where + ": " + e.what());
  }
}

std::pair<double, double> range(const YAML::Node &node, Dimension d, const std::string &where)
{
  if (!node.IsSequence() || node.size() != 2)
    throw std::invalid_argument(where + ": expected [low, high], e.g. [" + dimension_example(d) +
                                ", " + dimension_example(d) + "]");
  return {quantity(node[0], d, where), quantity(node[1], d, where)};
}

void refuse_unknown_keys(const YAML::Node &map, const std::vector<std::string> &known,
                         const std::string &where)
{
  for (const auto &kv : map)
  {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) == known.end())
    {
      std::string list;
      for (const auto &k : known)
        list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument(where + ": unknown key '" + key + "' (known: " + list + ")");
    }
  }
}

// The cells of one CSV line (the separator as the scan reader takes it: , ; or tab).
std::vector<std::string> cells(const std::string &line)
{
  char sep = ',';
  for (char c : {',', ';', '\t'})
    if (line.find(c) != std::string::npos)
    {
      sep = c;
      break;
    }
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, sep);)
  {
    const auto a = cell.find_first_not_of(" \t\r\"");
    const auto b = cell.find_last_not_of(" \t\r\"");
    out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  return out;
}

// The unit written in a column name ("tolerance_mT", "tol [G]"), or "".
std::string unit_in_name(const std::string &name)
{
  const auto at = name.find_last_of("_[( /");
  if (at == std::string::npos)
    return "";
  std::string u = name.substr(at + 1);
  while (!u.empty() && (u.back() == ']' || u.back() == ')'))
    u.pop_back();
  return u;
}

// The weight and tolerance columns of a profile target, row by row as the scan reader reads
// the samples (a header naming the columns is needed for them; otherwise defaults).
void read_weight_and_tolerance(const std::string &path, const FluxScan &scan,
                               double default_tolerance, ProfileTarget &t)
{
  t.weight.assign(scan.size(), 1.0);
  t.tolerance.assign(scan.size(), default_tolerance);
  std::ifstream in(path);
  std::string line;
  int weight_col = -1, tolerance_col = -1;
  double tolerance_unit = field_unit_factor(scan.field_unit);
  size_t row = 0;
  bool header = false;
  while (std::getline(in, line))
  {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    const auto c = cells(line);
    if (!header)
    {
      header = true;
      if (!c.empty() && !std::isalpha(static_cast<unsigned char>(c[0].empty() ? '0' : c[0][0])))
        return; // no header: angle, Bn[, Bt] only
      for (size_t j = 0; j < c.size(); ++j)
      {
        const std::string name = lower(c[j]);
        if (name.rfind("weight", 0) == 0)
          weight_col = int(j);
        if (name.rfind("tol", 0) == 0)
        {
          tolerance_col = int(j);
          const std::string u = unit_in_name(c[j]);
          if (!u.empty() && u != c[j])
            tolerance_unit = field_unit_factor(u);
        }
      }
      continue;
    }
    if (row >= scan.size())
      break;
    if (weight_col >= 0 && weight_col < int(c.size()) && !c[weight_col].empty())
      t.weight[row] = std::stod(c[weight_col]);
    if (tolerance_col >= 0 && tolerance_col < int(c.size()) && !c[tolerance_col].empty())
      t.tolerance[row] = std::stod(c[tolerance_col]) * tolerance_unit;
    if (t.weight[row] < 0.0 || !(t.tolerance[row] > 0.0))
      throw std::invalid_argument(path + ": sample " + std::to_string(row + 1) +
                                  ": a weight must be ≥ 0 and a tolerance > 0");
    ++row;
  }
}

PeakRequirement read_peak(const std::string &pole, const YAML::Node &n, const std::string &where)
{
  refuse_unknown_keys(n, {"peak", "peak_tolerance", "angle", "angle_tolerance"}, where);
  PeakRequirement r;
  r.pole = pole;
  if (n["peak"])
    r.peak = std::abs(quantity(n["peak"], Dimension::magnetic_flux_density, where + ".peak"));
  if (n["peak_tolerance"])
    r.peak_tolerance = quantity(n["peak_tolerance"], Dimension::magnetic_flux_density, where + ".peak_tolerance");
  if (n["angle"])
    r.angle = quantity(n["angle"], Dimension::angle, where + ".angle");
  if (n["angle_tolerance"])
    r.angle_tolerance = quantity(n["angle_tolerance"], Dimension::angle, where + ".angle_tolerance");
  if (!r.peak && !r.angle)
    throw std::invalid_argument(where + ": give peak and/or angle");
  if (!(r.peak_tolerance > 0.0) || !(r.angle_tolerance > 0.0))
    throw std::invalid_argument(where + ": tolerances must be > 0");
  return r;
}

FieldCeiling read_ceiling(const YAML::Node &n, const std::string &where)
{
  refuse_unknown_keys(n, {"from", "to", "level", "tolerance"}, where);
  if (!n["from"] || !n["to"] || !n["level"])
    throw std::invalid_argument(where + ": needs from, to and level (e.g. {from: 165 deg, to: 195 deg, level: 20 mT})");
  FieldCeiling c;
  c.from = quantity(n["from"], Dimension::angle, where + ".from");
  c.to = quantity(n["to"], Dimension::angle, where + ".to");
  c.level = quantity(n["level"], Dimension::magnetic_flux_density, where + ".level");
  if (n["tolerance"])
    c.tolerance = quantity(n["tolerance"], Dimension::magnetic_flux_density, where + ".tolerance");
  if (!(c.level > 0.0))
    throw std::invalid_argument(where + ".level must be > 0");
  return c;
}

void read_constraints_node(const YAML::Node &n, DesignConstraints &c, const std::string &where)
{
  refuse_unknown_keys(n, {"max_strength", "angle_range", "strength_range", "poles"}, where);
  if (n["max_strength"])
    c.max_strength = quantity(n["max_strength"], Dimension::magnetisation, where + ".max_strength");
  if (n["angle_range"])
    c.angle_range = quantity(n["angle_range"], Dimension::angle, where + ".angle_range");
  if (n["strength_range"])
  {
    const auto r = range(n["strength_range"], Dimension::dimensionless, where + ".strength_range");
    c.strength_factor_low = r.first;
    c.strength_factor_high = r.second;
  }
  if (n["poles"])
    for (const auto &kv : n["poles"])
    {
      const std::string name = kv.first.as<std::string>();
      const std::string at = where + ".poles." + name;
      refuse_unknown_keys(kv.second, {"fixed", "angle", "strength"}, at);
      auto &p = c.poles[name];
      if (kv.second["fixed"])
        p.fixed = kv.second["fixed"].as<bool>();
      if (kv.second["angle"])
        p.angle = range(kv.second["angle"], Dimension::angle, at + ".angle");
      if (kv.second["strength"])
      {
        auto s = range(kv.second["strength"], Dimension::magnetisation, at + ".strength");
        p.strength = std::make_pair(std::abs(s.first), std::abs(s.second));
      }
    }
}

YAML::Node load_yaml(const std::string &path)
{
  try
  {
    return YAML::LoadFile(path);
  }
  catch (const std::exception &e)
  {
    throw std::invalid_argument("cannot read " + path + ": " + e.what());
  }
}

} // namespace

std::vector<PoleLimits> DesignConstraints::limits_for(const std::vector<Pole> &poles) const
{
  for (const auto &kv : this->poles)
    if (std::none_of(poles.begin(), poles.end(), [&](const Pole &p) { return p.name == kv.first; }))
      throw std::invalid_argument("constraints name the pole '" + kv.first + "', which the case does not have");
  std::vector<PoleLimits> out;
  for (const Pole &p : poles)
  {
    PoleLimits l;
    const double M = std::abs(p.strength);
    l.angle_low = p.angle - angle_range;
    l.angle_high = p.angle + angle_range;
    l.strength_low = strength_factor_low * M;
    l.strength_high = strength_factor_high * M;
    const auto it = this->poles.find(p.name);
    if (it != this->poles.end())
    {
      l.fixed = it->second.fixed;
      if (it->second.angle)
      {
        // Unwrapped to the turn nearest the pole's own angle, so that [350°, 10°] works.
        double lo = it->second.angle->first, hi = it->second.angle->second;
        if (hi < lo)
          hi += two_pi;
        const double shift = two_pi * std::round((0.5 * (lo + hi) - p.angle) / two_pi);
        l.angle_low = lo - shift;
        l.angle_high = hi - shift;
      }
      if (it->second.strength)
      {
        l.strength_low = it->second.strength->first;
        l.strength_high = it->second.strength->second;
      }
    }
    l.strength_high = std::min(l.strength_high, max_strength);
    if (l.fixed)
    {
      l.angle_low = l.angle_high = p.angle;
      l.strength_low = l.strength_high = M;
    }
    if (!(l.strength_low <= l.strength_high) || !(l.angle_low <= l.angle_high))
      throw std::invalid_argument("pole " + p.name + ": its bounds are empty (low > high; is max_strength below the lower strength bound?)");
    out.push_back(l);
  }
  return out;
}

ProfileTarget read_profile_target(const std::string &path, double default_tolerance,
                                  const ScanReadOptions &options)
{
  const FluxScan scan = read_flux_scan(path, options);
  ProfileTarget t;
  t.source = path;
  t.angle = scan.angle;
  t.Bn = scan.Bn;
  t.Bt = scan.Bt;
  read_weight_and_tolerance(path, scan, default_tolerance, t);
  return t;
}

void read_design_constraints(const std::string &path, DesignConstraints &constraints)
{
  const YAML::Node root = load_yaml(path);
  if (!root["constraints"])
    throw std::invalid_argument(path + ": no 'constraints:' section");
  read_constraints_node(root["constraints"], constraints, "constraints");
}

DesignTarget read_design_spec(const std::string &path, double default_tolerance,
                              DesignConstraints &constraints)
{
  const YAML::Node root = load_yaml(path);
  refuse_unknown_keys(root, {"probe_radius", "poles", "field_below", "min_spacing", "release", "profile", "constraints"}, path);
  DesignTarget t;
  t.source = path;
  if (root["probe_radius"])
    t.probe_radius = quantity(root["probe_radius"], Dimension::length, "probe_radius");
  if (root["poles"])
    for (const auto &kv : root["poles"])
      t.peaks.push_back(read_peak(kv.first.as<std::string>(), kv.second, "poles." + kv.first.as<std::string>()));
  if (root["field_below"])
    for (size_t i = 0; i < root["field_below"].size(); ++i)
      t.ceilings.push_back(read_ceiling(root["field_below"][i], "field_below[" + std::to_string(i) + "]"));
  if (root["min_spacing"])
    t.min_spacing = quantity(root["min_spacing"], Dimension::angle, "min_spacing");
  if (root["release"])
  {
    const YAML::Node n = root["release"];
    refuse_unknown_keys(n, {"from", "to", "margin"}, "release");
    if (!n["from"] || !n["to"])
      throw std::invalid_argument("release: needs from and to (e.g. {from: 180 deg, to: 200 deg, margin: 0.5})");
    ReleaseRequirement r;
    r.from = quantity(n["from"], Dimension::angle, "release.from");
    r.to = quantity(n["to"], Dimension::angle, "release.to");
    if (n["margin"])
      r.margin = quantity(n["margin"], Dimension::dimensionless, "release.margin");
    t.release = r;
  }
  if (root["profile"])
  {
    std::filesystem::path p = root["profile"].as<std::string>();
    if (p.is_relative())
      p = std::filesystem::path(path).parent_path() / p;
    t.profile = read_profile_target(p.string(), default_tolerance);
  }
  if (root["constraints"])
    read_constraints_node(root["constraints"], constraints, "constraints");
  if (t.empty())
    throw std::invalid_argument(path + ": the specification asks for nothing (give poles, field_below, min_spacing, release or profile)");
  return t;
}

DesignTarget read_design_target(const std::string &path, double default_tolerance,
                                DesignConstraints &constraints, const ScanReadOptions &options)
{
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".yaml" || ext == ".yml")
    return read_design_spec(path, default_tolerance, constraints);
  DesignTarget t;
  t.source = path;
  t.profile = read_profile_target(path, default_tolerance, options);
  return t;
}

} // namespace magbrush
