// Reading gaussmeter scans (see flux_scan.h for the accepted format).
#include "calibration/flux_scan.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

namespace magbrush {

namespace {

constexpr double pi = M_PI;

std::string lower(std::string s)
{
  for (char &c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string &s)
{
  const auto b = s.find_first_not_of(" \t\r\n\"'");
  if (b == std::string::npos)
    return "";
  const auto e = s.find_last_not_of(" \t\r\n\"'");
  return s.substr(b, e - b + 1);
}

// The separator of a line: the first of , ; tab that occurs, else blanks.
char detect_separator(const std::string &line)
{
  for (char c : {',', ';', '\t'})
    if (line.find(c) != std::string::npos)
      return c;
  return ' ';
}

std::vector<std::string> split(const std::string &line, char sep)
{
  std::vector<std::string> cells;
  if (sep == ' ')
  {
    std::istringstream in(line);
    std::string cell;
    while (in >> cell)
      cells.push_back(cell);
    return cells;
  }
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, sep))
    cells.push_back(trim(cell));
  if (!line.empty() && line.back() == sep)
    cells.push_back("");
  return cells;
}

bool parse_number(const std::string &cell, double &value)
{
  const std::string s = trim(cell);
  if (s.empty())
    return false;
  errno = 0;
  char *end = nullptr;
  value = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE;
}

enum class Role { none, angle, bn, bt };

// A header cell split into the quantity's name and its unit: "Bn [mT]", "Bn (mT)", "Bn_mT",
// "Bn/mT", "angle_deg" → ("bn", "mT").
struct HeaderCell
{
  std::string name; // lower case, without unit and separators
  std::string unit; // as written ("" when none)
};

bool is_angle_unit(const std::string &u)
{
  const std::string l = lower(u);
  return l == "deg" || l == "degree" || l == "degrees" || l == "rad" || l == "radian" ||
         l == "radians" || u == "°";
}

bool is_field_unit(const std::string &u)
{
  const std::string l = lower(u);
  return l == "t" || l == "mt" || l == "g" || l == "gauss" || l == "kg" || l == "tesla" ||
         l == "millitesla";
}

std::string normalised(const std::string &s)
{
  std::string name;
  for (char c : lower(s))
    if (c != '_' && c != ' ' && c != '-' && c != '.')
      name += c;
  return name;
}

Role role_of_name(const std::string &name)
{
  static const char *angle_names[] = {"angle", "theta", "phi", "deg", "degree", "degrees",
                                      "rad", "position", "pos", "θ"};
  static const char *bn_names[] = {"bn", "br", "bnormal", "normal", "bnorm", "bradial",
                                   "radial"};
  static const char *bt_names[] = {"bt", "btheta", "btan", "btangential", "tangential",
                                   "btang", "bθ", "bphi"};
  for (const char *n : angle_names)
    if (name == n)
      return Role::angle;
  for (const char *n : bn_names)
    if (name == n)
      return Role::bn;
  for (const char *n : bt_names)
    if (name == n)
      return Role::bt;
  return Role::none;
}

HeaderCell split_header_cell(const std::string &raw)
{
  std::string s = trim(raw);
  HeaderCell h;
  const auto open = s.find_first_of("[(");
  if (open != std::string::npos)
  {
    const auto close = s.find_first_of("])", open);
    h.unit = trim(s.substr(open + 1, close == std::string::npos ? std::string::npos
                                                                : close - open - 1));
    s = trim(s.substr(0, open));
  }
  else if (role_of_name(normalised(s)) == Role::none)
  {
    // "Bn_mT", "angle_deg", "Bn/G", "Bt mT": a unit after the last separator. (Not when the
    // whole cell is already a name, as in "B_t" — the t there is not tesla.)
    const auto cut = s.find_last_of("_/ ");
    if (cut != std::string::npos)
    {
      const std::string tail = s.substr(cut + 1);
      if (is_angle_unit(tail) || is_field_unit(tail))
      {
        h.unit = tail;
        s = s.substr(0, cut);
      }
    }
  }
  h.name = normalised(s);
  // A bare unit as the column name ("deg", "rad") names the angle column and its unit.
  if (is_angle_unit(h.name) && h.unit.empty())
    h.unit = h.name;
  return h;
}

Role role_of(const HeaderCell &h) { return role_of_name(h.name); }

std::string where(const std::string &name, int line)
{
  return name + ":" + std::to_string(line) + ": ";
}

} // namespace

double angle_unit_factor(const std::string &unit)
{
  const std::string l = lower(unit);
  if (l == "deg" || l == "degree" || l == "degrees" || unit == "°")
    return pi / 180.0;
  if (l == "rad" || l == "radian" || l == "radians")
    return 1.0;
  throw ScanError("unknown angle unit '" + unit + "'; use deg or rad");
}

double field_unit_factor(const std::string &unit)
{
  const std::string l = lower(unit);
  if (l == "t" || l == "tesla")
    return 1.0;
  if (l == "mt" || l == "millitesla")
    return 1e-3;
  if (l == "g" || l == "gauss")
    return 1e-4;
  if (l == "kg")
    return 0.1;
  throw ScanError("unknown flux-density unit '" + unit + "'; use T, mT, G or kG");
}

FluxScan read_flux_scan(const std::string &path, const ScanReadOptions &options)
{
  std::ifstream in(path);
  if (!in)
    throw ScanError(path + ": cannot open the scan file (check the path and permissions)");
  return parse_flux_scan(in, path, options);
}

FluxScan parse_flux_scan(std::istream &in, const std::string &name,
                         const ScanReadOptions &options)
{
  FluxScan scan;
  scan.source = name;
  int column_angle = 0, column_bn = 1, column_bt = -1;
  size_t columns = 0;
  char sep = ',';
  bool header_seen = false;
  std::string header_angle_unit, header_field_unit, header_bt_unit;
  std::vector<double> raw_angle, raw_bn, raw_bt;

  std::string line;
  int number = 0;
  while (std::getline(in, line))
  {
    ++number;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    const std::string t = trim(line);
    if (t.empty())
      continue;
    if (t[0] == '#')
    {
      scan.comments.push_back(trim(t.substr(1)));
      continue;
    }
    if (!header_seen && raw_angle.empty())
    {
      sep = detect_separator(t);
      const auto cells = split(t, sep);
      double dummy;
      if (!parse_number(cells[0], dummy))
      {
        // The header: find the columns by name.
        header_seen = true;
        column_angle = column_bn = column_bt = -1;
        columns = cells.size();
        std::string bn_unit, bt_unit;
        for (size_t c = 0; c < cells.size(); ++c)
        {
          const HeaderCell h = split_header_cell(cells[c]);
          const Role role = role_of(h);
          if (role == Role::angle && column_angle < 0)
          {
            column_angle = static_cast<int>(c);
            scan.angle_column = cells[c];
            header_angle_unit = h.unit;
          }
          else if (role == Role::bn && column_bn < 0)
          {
            column_bn = static_cast<int>(c);
            scan.bn_column = cells[c];
            bn_unit = h.unit;
          }
          else if (role == Role::bt && column_bt < 0)
          {
            column_bt = static_cast<int>(c);
            scan.bt_column = cells[c];
            bt_unit = h.unit;
          }
        }
        if (column_angle < 0 || column_bn < 0)
          throw ScanError(where(name, number) + "the header '" + t + "' has no " +
                          (column_angle < 0 ? "angle" : "normal flux (Bn)") +
                          " column; expected columns like angle_deg, Bn_mT, Bt_mT "
                          "(names: angle/theta/deg, Bn/B_n/Br, Bt/B_t/Btheta)");
        if (!bn_unit.empty() && !bt_unit.empty() && lower(bn_unit) != lower(bt_unit))
          throw ScanError(where(name, number) + "Bn is in " + bn_unit + " but Bt in " + bt_unit +
                          "; both columns must use the same unit");
        header_field_unit = bn_unit.empty() ? bt_unit : bn_unit;
        if (!header_angle_unit.empty())
          angle_unit_factor(header_angle_unit); // validates
        if (!header_field_unit.empty())
          field_unit_factor(header_field_unit);
        continue;
      }
      // No header: angle, Bn[, Bt] in this order.
      columns = cells.size();
      column_angle = 0;
      column_bn = 1;
      column_bt = cells.size() >= 3 ? 2 : -1;
      if (cells.size() < 2)
        throw ScanError(where(name, number) + "expected at least two columns (angle, Bn), found " +
                        std::to_string(cells.size()));
      scan.notes.push_back("no header line: columns taken as angle, Bn" +
                           std::string(column_bt >= 0 ? ", Bt" : ""));
    }
    const auto cells = split(t, sep);
    if (cells.size() != columns)
      throw ScanError(where(name, number) + "expected " + std::to_string(columns) +
                      " columns, found " + std::to_string(cells.size()) + " in '" + t + "'");
    auto number_in = [&](int column, const char *what) {
      double v;
      std::string cell = cells[column];
      // A decimal comma ("1,25") is fine when the separator is not a comma.
      if (sep != ',' && cell.find(',') != std::string::npos && cell.find('.') == std::string::npos)
        cell[cell.find(',')] = '.';
      if (!parse_number(cell, v))
        throw ScanError(where(name, number) + "the " + what + " cell '" + cells[column] +
                        "' (column " + std::to_string(column + 1) + ") is not a number");
      if (!std::isfinite(v))
        throw ScanError(where(name, number) + "the " + what + " cell '" + cells[column] +
                        "' is not a finite number");
      return v;
    };
    raw_angle.push_back(number_in(column_angle, "angle"));
    raw_bn.push_back(number_in(column_bn, "Bn"));
    if (column_bt >= 0)
      raw_bt.push_back(number_in(column_bt, "Bt"));
    scan.line.push_back(number);
  }
  if (in.bad())
    throw ScanError(name + ": read error");

  // Units: option > header > assumption.
  auto resolve = [&](const std::string &option, const std::string &header, const char *what,
                     const char *fallback, const char *flag) {
    if (!option.empty())
    {
      if (!header.empty() && lower(option) != lower(header))
        scan.notes.push_back(std::string("--") + flag + " " + option + " overrides the header's " +
                             what + " unit " + header);
      return option;
    }
    if (!header.empty())
      return header;
    scan.notes.push_back(std::string("no ") + what + " unit in the header or --" + flag +
                         ": assuming " + fallback);
    return std::string(fallback);
  };
  scan.angle_unit = resolve(options.angle_unit, header_angle_unit, "angle", "deg", "angle-unit");
  scan.field_unit = resolve(options.field_unit, header_field_unit, "flux-density", "mT",
                            "field-unit");
  const double fa = angle_unit_factor(scan.angle_unit);
  const double fb = field_unit_factor(scan.field_unit);

  if (raw_angle.size() < std::max<size_t>(options.min_points, 2))
    throw ScanError(name + ": the scan has " + std::to_string(raw_angle.size()) +
                    " data points; at least " + std::to_string(options.min_points) +
                    " are needed (is the file empty, or all comments?)");
  if (options.require_tangential && raw_bt.empty())
    throw ScanError(name + ": no tangential (Bt) column, which this operation needs");

  // An encoder that wraps (…, 358, 359, 0, 1, …) is unwrapped: a jump back by more than half
  // a turn against the scan's direction is a wrap, not a step.
  const bool increasing = raw_angle[1] > raw_angle[0];
  const double turn = 2.0 * pi / fa;
  double unwrap = 0.0;
  for (size_t k = 1; k < raw_angle.size(); ++k)
  {
    const double step = raw_angle[k] + unwrap - raw_angle[k - 1];
    if (increasing ? step < -0.5 * turn : step > 0.5 * turn)
    {
      unwrap += increasing ? turn : -turn;
      scan.notes.push_back("the angle wraps around at line " + std::to_string(scan.line[k]) +
                           "; unwrapped");
    }
    raw_angle[k] += unwrap;
  }
  // Strictly monotone angles, at most one turn.
  for (size_t k = 1; k < raw_angle.size(); ++k)
  {
    const double step = raw_angle[k] - raw_angle[k - 1];
    if (!(increasing ? step > 0 : step < 0))
      throw ScanError(where(name, scan.line[k]) + "angle " + std::to_string(raw_angle[k]) +
                      " after " + std::to_string(raw_angle[k - 1]) +
                      ": the angles must be strictly " + (increasing ? "increasing" : "decreasing") +
                      " (one scan, one direction, no repeated points)");
  }
  const double span = std::abs(raw_angle.back() - raw_angle.front()) * fa;
  if (span > 2.0 * pi * (1.0 + 1e-9))
    throw ScanError(name + ": the angles span " + std::to_string(span * 180.0 / pi) +
                    " deg, more than one turn" +
                    (lower(scan.angle_unit).rfind("rad", 0) == 0
                         ? std::string(" (are they degrees? pass --angle-unit deg)")
                         : std::string("; keep one revolution")));
  if (lower(scan.angle_unit).rfind("deg", 0) == 0 && header_angle_unit.empty() &&
      options.angle_unit.empty() && span < 2.0 * pi * pi / 180.0 * 1.01 && raw_angle.size() > 20)
    scan.notes.push_back("the angles span only " + std::to_string(span * 180 / pi) +
                         " deg; if they are radians pass --angle-unit rad");

  const double direction = options.clockwise ? -1.0 : 1.0;
  for (size_t k = 0; k < raw_angle.size(); ++k)
  {
    scan.angle.push_back(direction * raw_angle[k] * fa + options.angle_offset);
    scan.Bn.push_back(raw_bn[k] * fb);
    if (!raw_bt.empty())
      scan.Bt.push_back((options.flip_tangential ? -direction : direction) * raw_bt[k] * fb);
  }
  double largest = 0.0;
  for (double b : scan.Bn)
    largest = std::max(largest, std::abs(b));
  if (header_field_unit.empty() && options.field_unit.empty() && largest < 2e-3)
    scan.notes.push_back("the largest |Bn| is below 2 mT when read as mT; if the values are "
                         "tesla pass --field-unit T");
  return scan;
}

// Periodic cubic Hermite interpolation with three-point (non-uniform) slopes.
FluxScan rotated_scan(FluxScan scan, double angle)
{
  for (double &a : scan.angle)
    a += angle;
  return scan;
}

std::vector<double> interpolate_periodic(const std::vector<double> &angle,
                                         const std::vector<double> &value,
                                         const std::vector<double> &at)
{
  const size_t n = angle.size();
  if (n < 3 || value.size() != n)
    throw std::invalid_argument("interpolate_periodic: need ≥ 3 samples with matching values");
  // Sort by angle wrapped into [0, 2π).
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto wrap = [](double a) {
    a = std::fmod(a, 2.0 * pi);
    return a < 0 ? a + 2.0 * pi : a;
  };
  std::vector<double> x(n), y(n);
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return wrap(angle[a]) < wrap(angle[b]); });
  for (size_t i = 0; i < n; ++i)
  {
    x[i] = wrap(angle[order[i]]);
    y[i] = value[order[i]];
  }
  // Drop a duplicate of the first point one turn later (0 and 360 both present).
  while (x.size() > 3 && x.back() - x.front() >= 2.0 * pi - 1e-12)
  {
    x.pop_back();
    y.pop_back();
  }
  const size_t m = x.size();
  auto X = [&](long i) { // periodic extension
    const long k = ((i % long(m)) + long(m)) % long(m);
    return x[k] + 2.0 * pi * std::floor(double(i) / double(m));
  };
  auto Y = [&](long i) { return y[((i % long(m)) + long(m)) % long(m)]; };
  auto slope = [&](long i) {
    const double h0 = X(i) - X(i - 1), h1 = X(i + 1) - X(i);
    const double d0 = (Y(i) - Y(i - 1)) / h0, d1 = (Y(i + 1) - Y(i)) / h1;
    return (h1 * d0 + h0 * d1) / (h0 + h1);
  };
  std::vector<double> out;
  out.reserve(at.size());
  for (double a : at)
  {
    const double t = wrap(a);
    // Interval [X(i), X(i+1)) containing t (i = −1 is the wrap-around interval).
    long i = static_cast<long>(std::upper_bound(x.begin(), x.end(), t) - x.begin()) - 1;
    const double x0 = X(i), x1 = X(i + 1);
    const double h = x1 - x0, s = (t - x0) / h;
    const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
    const double h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
    out.push_back(h00 * Y(i) + h10 * h * slope(i) + h01 * Y(i + 1) + h11 * h * slope(i + 1));
  }
  return out;
}

} // namespace magbrush
