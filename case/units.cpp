// Units by dimensional analysis: every unit symbol carries exponents over the base
// dimensions (m, kg, s, A, rad) and a factor to SI. A unit expression multiplies them out,
// and the result is accepted only when its exponents equal those of the expected dimension.
#include "case/units.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace magbrush {

namespace {

// Exponents over (metre, kilogram, second, ampere, radian).
using Exponents = std::array<int, 5>;

Exponents operator+(Exponents a, const Exponents &b)
{
  for (int i = 0; i < 5; ++i)
    a[i] += b[i];
  return a;
}
Exponents scaled(Exponents a, int k)
{
  for (auto &e : a)
    e *= k;
  return a;
}

struct UnitSymbol
{
  const char *symbol;
  Exponents exponents;
  double factor;   // SI value of one unit
  bool prefixable; // accepts n, u, m, k, M, ... in front
};

constexpr double pi = 3.14159265358979323846;

const std::vector<UnitSymbol> &unit_symbols()
{
  //                                   m  kg  s  A rad
  static const std::vector<UnitSymbol> table = {
      {"m", {1, 0, 0, 0, 0}, 1.0, true},
      {"g", {0, 1, 0, 0, 0}, 1e-3, true},
      {"s", {0, 0, 1, 0, 0}, 1.0, true},
      {"min", {0, 0, 1, 0, 0}, 60.0, false},
      {"h", {0, 0, 1, 0, 0}, 3600.0, false},
      {"A", {0, 0, 0, 1, 0}, 1.0, true},
      {"rad", {0, 0, 0, 0, 1}, 1.0, true},
      {"deg", {0, 0, 0, 0, 1}, pi / 180.0, false},
      {"rev", {0, 0, 0, 0, 1}, 2.0 * pi, false},
      {"rpm", {0, 0, -1, 0, 1}, 2.0 * pi / 60.0, false},
      {"Hz", {0, 0, -1, 0, 0}, 1.0, true},
      {"N", {1, 1, -2, 0, 0}, 1.0, true},
      {"Pa", {-1, 1, -2, 0, 0}, 1.0, true},
      {"J", {2, 1, -2, 0, 0}, 1.0, true},
      {"W", {2, 1, -3, 0, 0}, 1.0, true},
      {"C", {0, 0, 1, 1, 0}, 1.0, true},
      {"V", {2, 1, -3, -1, 0}, 1.0, true},
      {"T", {0, 1, -2, -1, 0}, 1.0, true},
      {"G", {0, 1, -2, -1, 0}, 1e-4, true}, // gauss
      {"%", {0, 0, 0, 0, 0}, 1e-2, false},
  };
  return table;
}

struct Prefix
{
  char symbol;
  double factor;
};
const std::array<Prefix, 9> prefixes = {{{'f', 1e-15},
                                         {'p', 1e-12},
                                         {'n', 1e-9},
                                         {'u', 1e-6},
                                         {'m', 1e-3},
                                         {'c', 1e-2},
                                         {'k', 1e3},
                                         {'M', 1e6},
                                         {'G', 1e9}}};

struct DimensionInfo
{
  Dimension dimension;
  Exponents exponents;
  const char *description;
  const char *example;
  const char *si;
};

const std::vector<DimensionInfo> &dimension_table()
{
  static const std::vector<DimensionInfo> table = {
      {Dimension::dimensionless, {0, 0, 0, 0, 0}, "a plain number", "0.35", ""},
      {Dimension::length, {1, 0, 0, 0, 0}, "a length", "25 mm", "m"},
      {Dimension::time, {0, 0, 1, 0, 0}, "a time", "20 ns", "s"},
      {Dimension::angle, {0, 0, 0, 0, 1}, "an angle", "90 deg", "rad"},
      {Dimension::angular_velocity, {0, 0, -1, 0, 1}, "an angular velocity", "219 rpm", "rad/s"},
      {Dimension::magnetic_flux_density, {0, 1, -2, -1, 0}, "a magnetic flux density", "130 mT", "T"},
      {Dimension::magnetisation, {-1, 0, 0, 1, 0}, "a magnetisation", "170 kA/m", "A/m"},
      {Dimension::voltage, {2, 1, -3, -1, 0}, "a voltage", "-600 V", "V"},
      {Dimension::pressure, {-1, 1, -2, 0, 0}, "a pressure or modulus", "1000 MPa", "Pa"},
      {Dimension::density, {-3, 1, 0, 0, 0}, "a density", "2200 kg/m^3", "kg/m^3"},
      {Dimension::charge_to_mass, {0, -1, 1, 1, 0}, "a charge-to-mass ratio", "-30 uC/g", "C/kg"},
      {Dimension::surface_charge, {-2, 0, 1, 1, 0}, "a surface charge density", "-100 uC/m^2", "C/m^2"},
      {Dimension::viscosity, {-1, 1, -1, 0, 0}, "a viscosity", "1.81e-5 Pa*s", "Pa*s"},
      {Dimension::energy, {2, 1, -2, 0, 0}, "an energy", "1e-19 J", "J"},
      {Dimension::velocity, {1, 0, -1, 0, 0}, "a velocity", "0.1 m/s", "m/s"},
      {Dimension::mass, {0, 1, 0, 0, 0}, "a mass", "2 g", "kg"},
      {Dimension::acceleration, {1, 0, -2, 0, 0}, "an acceleration", "-9.81 m/s^2", "m/s^2"},
      {Dimension::frequency, {0, 0, -1, 0, 0}, "a frequency", "2 kHz", "Hz"},
      {Dimension::charge, {0, 0, 1, 1, 0}, "a charge", "-5 fC", "C"},
      {Dimension::force, {1, 1, -2, 0, 0}, "a force", "1 mN", "N"},
      {Dimension::electric_field, {1, 1, -3, -1, 0}, "an electric field", "2 kV/mm", "V/m"},
      {Dimension::inverse_angle_squared, {0, 0, 0, 0, -2}, "a shape factor per radian squared", "10 rad^-2", "rad^-2"},
      {Dimension::areal_mass, {-2, 1, 0, 0, 0}, "a mass per area", "0.4 kg/m^2", "kg/m^2"},
      {Dimension::linear_mass, {-1, 1, 0, 0, 0}, "a mass per length", "0.5 kg/m", "kg/m"},
  };
  return table;
}

const DimensionInfo &info(Dimension d)
{
  for (const auto &i : dimension_table())
    if (i.dimension == d)
      return i;
  throw std::logic_error("units: dimension without a table entry");
}

std::string describe_exponents(const Exponents &e)
{
  for (const auto &i : dimension_table())
    if (i.exponents == e)
      return i.description;
  static const char *base[5] = {"m", "kg", "s", "A", "rad"};
  std::string s = "units of";
  for (int k = 0; k < 5; ++k)
    if (e[k] != 0)
      s += std::string(" ") + base[k] + (e[k] == 1 ? "" : "^" + std::to_string(e[k]));
  return s;
}

// Unicode spellings users paste from papers: µ (micro sign), μ (Greek mu), ·, ², ³, °.
std::string normalise_unicode(const std::string &text)
{
  const std::pair<const char *, const char *> replacements[] = {
      {"\xC2\xB5", "u"}, {"\xCE\xBC", "u"}, {"\xC2\xB7", "*"}, {"\xC2\xB2", "^2"},
      {"\xC2\xB3", "^3"}, {"\xC2\xB0", "deg"}, {"**", "^"}, {"\xE2\x88\x92", "-"}};
  std::string s = text;
  for (const auto &[from, to] : replacements)
  {
    std::string::size_type pos = 0;
    const std::string f = from;
    while ((pos = s.find(f, pos)) != std::string::npos)
    {
      s.replace(pos, f.size(), to);
      pos += std::string(to).size();
    }
  }
  return s;
}

// A symbol with optional prefix: whole-symbol matches win ("min", "G" = gauss), then
// prefix + symbol ("mm", "GPa", "uC").
bool lookup_symbol(const std::string &symbol, Exponents &exponents, double &factor)
{
  for (const auto &u : unit_symbols())
    if (symbol == u.symbol)
    {
      exponents = u.exponents;
      factor = u.factor;
      return true;
    }
  if (symbol.size() >= 2)
    for (const auto &p : prefixes)
      if (symbol[0] == p.symbol)
        for (const auto &u : unit_symbols())
          if (u.prefixable && symbol.compare(1, std::string::npos, u.symbol) == 0)
          {
            exponents = u.exponents;
            factor = p.factor * u.factor;
            return true;
          }
  return false;
}

// Long inputs are cut in messages (a case value is short; a pasted blob should not flood).
std::string shortened(const std::string &text)
{
  return text.size() <= 80 ? text : text.substr(0, 60) + "...(" + std::to_string(text.size()) + " characters)";
}

[[noreturn]] void fail(const std::string &text, Dimension expected, const std::string &why)
{
  throw UnitError("expected " + dimension_description(expected) + " (e.g. " +
                  dimension_example(expected) + "), found '" + shortened(text) + "'" +
                  (why.empty() ? "" : ": " + why));
}

// Parses a leading decimal number (no hex, no inf/nan). Returns characters consumed (0: none).
size_t scan_number(const std::string &s)
{
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-'))
    ++i;
  size_t digits = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])))
    ++i, ++digits;
  if (i < s.size() && s[i] == '.')
  {
    ++i;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])))
      ++i, ++digits;
  }
  if (digits == 0)
    return 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E'))
  {
    size_t j = i + 1;
    if (j < s.size() && (s[j] == '+' || s[j] == '-'))
      ++j;
    size_t exp_digits = 0;
    while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j])))
      ++j, ++exp_digits;
    if (exp_digits > 0)
      i = j;
  }
  return i;
}

// The message for a refused bare number (defined with the display units below).
std::string bare_number_message(const std::string &number_text, double number, Dimension d, double typical_si);

} // namespace

std::string dimension_description(Dimension d) { return info(d).description; }
std::string dimension_example(Dimension d) { return info(d).example; }
std::string si_unit(Dimension d) { return info(d).si; }

double parse_quantity(const std::string &original, Dimension expected, BareNumber bare, double typical_si)
{
  const std::string text = normalise_unicode(original);
  size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos)
    fail(original, expected, "the value is empty");
  const size_t end = text.find_last_not_of(" \t") + 1;
  const std::string s = text.substr(begin, end - begin);

  const size_t n = scan_number(s);
  if (n == 0)
    fail(original, expected, "it does not start with a number");
  const double number = std::strtod(s.substr(0, n).c_str(), nullptr);
  if (!std::isfinite(number))
    fail(original, expected, "the number is out of range");

  // Unit expression: factors joined by '*', '/', or spaces; '^' gives an integer exponent.
  Exponents exponents{0, 0, 0, 0, 0};
  double factor = 1.0;
  size_t i = n;
  char pending = 0; // '*' or '/' waiting for its symbol
  bool any_symbol = false;
  while (i < s.size())
  {
    const char c = s[i];
    if (c == ' ' || c == '\t')
    {
      ++i;
      continue;
    }
    if (c == '*' || c == '/')
    {
      if (pending != 0 || (c == '*' && i == n))
        fail(original, expected, "misplaced '" + std::string(1, c) + "' in the unit");
      pending = c;
      ++i;
      continue;
    }
    size_t j = i;
    while (j < s.size() && (std::isalpha(static_cast<unsigned char>(s[j])) || s[j] == '%'))
      ++j;
    if (j == i)
      fail(original, expected, "unexpected character '" + std::string(1, c) + "' in the unit");
    const std::string symbol = s.substr(i, j - i);
    Exponents e;
    double f;
    if (!lookup_symbol(symbol, e, f))
      fail(original, expected,
           "unknown unit '" + shortened(symbol) +
               "' (units: m, s, g, rad, deg, rpm, Hz, N, Pa, J, C, V, T, G (gauss), A, % with "
               "prefixes f p n u m c k M G, combined with * / ^)");
    int power = 1;
    i = j;
    if (i < s.size() && s[i] == '^')
    {
      size_t k = i + 1;
      if (k < s.size() && (s[k] == '-' || s[k] == '+'))
        ++k;
      const size_t digits_begin = k;
      while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k])))
        ++k;
      if (k == digits_begin || k - digits_begin > 2)
        fail(original, expected, "'^' must be followed by a small integer exponent");
      power = std::atoi(s.substr(i + 1, k - i - 1).c_str());
      i = k;
    }
    const int direction = (pending == '/') ? -1 : 1;
    exponents = exponents + scaled(e, power * direction);
    factor *= std::pow(f, power * direction);
    pending = 0;
    any_symbol = true;
  }
  if (pending != 0)
    fail(original, expected, "the unit ends with '" + std::string(1, pending) + "'");

  // A bare number: a plain number, a zero, or (BareNumber::si) SI; otherwise refused.
  if (!any_symbol && expected != Dimension::dimensionless && number != 0.0 && bare == BareNumber::refused)
    throw UnitError(bare_number_message(s, number, expected, typical_si));
  if (any_symbol && exponents != info(expected).exponents)
    fail(original, expected, "that is " + describe_exponents(exponents));
  const double value = number * factor;
  if (!std::isfinite(value))
    fail(original, expected, "the value is out of range");
  return value;
}

namespace {
struct DisplayUnit
{
  const char *symbol;
  double factor;
};

// Display units per dimension, largest first; the first one giving a magnitude >= 1 is
// used (the last one otherwise); zero uses the preferred (first listed after `preferred`).
struct DisplayChoice
{
  std::vector<DisplayUnit> units;
  size_t preferred = 0;
};

DisplayChoice display_units(Dimension d)
{
  switch (d)
  {
  case Dimension::dimensionless: return {{{"", 1.0}}};
  case Dimension::length: return {{{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}, {"nm", 1e-9}}, 1};
  case Dimension::time: return {{{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"ns", 1e-9}}, 0};
  case Dimension::angle: return {{{"deg", pi / 180.0}}};
  case Dimension::angular_velocity: return {{{"rpm", 2.0 * pi / 60.0}}};
  case Dimension::magnetic_flux_density: return {{{"T", 1.0}, {"mT", 1e-3}}, 1};
  case Dimension::magnetisation: return {{{"MA/m", 1e6}, {"kA/m", 1e3}, {"A/m", 1.0}}, 1};
  case Dimension::voltage: return {{{"kV", 1e3}, {"V", 1.0}}, 1};
  case Dimension::pressure: return {{{"MPa", 1e6}, {"kPa", 1e3}, {"Pa", 1.0}}, 0};
  case Dimension::density: return {{{"kg/m^3", 1.0}}};
  case Dimension::charge_to_mass: return {{{"uC/g", 1e-3}}};
  case Dimension::surface_charge: return {{{"uC/m^2", 1e-6}}};
  case Dimension::viscosity: return {{{"Pa*s", 1.0}}};
  case Dimension::energy: return {{{"J", 1.0}}};
  case Dimension::velocity: return {{{"m/s", 1.0}}};
  case Dimension::mass: return {{{"kg", 1.0}, {"g", 1e-3}, {"mg", 1e-6}, {"ug", 1e-9}, {"ng", 1e-12}}, 0};
  case Dimension::acceleration: return {{{"m/s^2", 1.0}}};
  case Dimension::frequency: return {{{"kHz", 1e3}, {"Hz", 1.0}}, 1};
  case Dimension::charge: return {{{"C", 1.0}, {"nC", 1e-9}, {"pC", 1e-12}, {"fC", 1e-15}}, 3};
  case Dimension::force: return {{{"N", 1.0}, {"mN", 1e-3}, {"uN", 1e-6}, {"nN", 1e-9}}, 0};
  case Dimension::electric_field: return {{{"MV/m", 1e6}, {"kV/m", 1e3}, {"V/m", 1.0}}, 2};
  case Dimension::inverse_angle_squared: return {{{"rad^-2", 1.0}}};
  case Dimension::areal_mass: return {{{"kg/m^2", 1.0}}};
  case Dimension::linear_mass: return {{{"kg/m", 1.0}}};
  }
  return {{{"", 1.0}}};
}

std::string format_number(double x)
{
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6g", x);
  return buffer;
}

// The units a bare number is weighed against: the display units and a few more that case
// files use, with the scale a value of this dimension usually has in this code.
struct UsualUnits
{
  std::vector<DisplayUnit> units;
  double typical; // SI
};

UsualUnits usual_units(Dimension d)
{
  std::vector<DisplayUnit> units = display_units(d).units;
  const auto add = [&](const char *symbol, double factor) { units.push_back({symbol, factor}); };
  double typical = 1.0;
  switch (d)
  {
  case Dimension::length: typical = 1e-3; break;
  case Dimension::time: typical = 1e-3; break;
  case Dimension::angle: add("rad", 1.0); typical = 0.5; break;
  case Dimension::angular_velocity: add("rad/s", 1.0); typical = 100.0 * 2.0 * pi / 60.0; break;
  case Dimension::magnetic_flux_density: typical = 0.1; break;
  case Dimension::magnetisation: typical = 1e5; break;
  case Dimension::voltage: typical = 100.0; break;
  case Dimension::pressure: add("GPa", 1e9); typical = 1e6; break;
  case Dimension::density: add("g/cm^3", 1e3); typical = 1e3; break;
  case Dimension::charge_to_mass: add("C/kg", 1.0); typical = 0.03; break;
  case Dimension::surface_charge: add("C/m^2", 1.0); typical = 1e-4; break;
  case Dimension::mass: typical = 1e-3; break;
  case Dimension::frequency: typical = 1e3; break;
  case Dimension::charge: typical = 1e-15; break;
  case Dimension::force: typical = 1e-3; break;
  case Dimension::electric_field: typical = 1e6; break;
  default: break;
  }
  return {units, typical};
}

std::string bare_number_message(const std::string &number_text, double number, Dimension d, double typical_si)
{
  const std::vector<std::string> units = likely_units(number, d, typical_si);
  const std::string written = shortened(number_text);
  std::string message = written + " \xE2\x80\x94 " + dimension_description(d) + " needs a unit: ";
  for (size_t k = 0; k < units.size(); ++k)
    message += (k ? " or " : "") + written + " " + units[k];
  return message + "? (a bare number is not read as SI; only 0 may go without a unit)";
}
} // namespace

std::vector<std::string> likely_units(double number, Dimension d, double typical_si)
{
  const UsualUnits usual = usual_units(d);
  const double typical = (typical_si != 0.0 && std::isfinite(typical_si)) ? std::abs(typical_si) : usual.typical;
  const double magnitude = std::abs(number);
  std::vector<std::pair<double, std::string>> ranked; // log10 distance from the typical scale
  for (const auto &u : usual.units)
    ranked.emplace_back(magnitude > 0.0 ? std::abs(std::log10(magnitude * u.factor / typical)) : 0.0, u.symbol);
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto &a, const auto &b) { return a.first < b.first; });
  std::vector<std::string> out{ranked.front().second};
  // A second unit when the number is nearly as plausible in it (within a factor 10).
  if (ranked.size() > 1 && ranked[1].first < ranked[0].first + 1.0)
    out.push_back(ranked[1].second);
  return out;
}

std::string format_quantity(double si_value, Dimension d)
{
  const DisplayChoice choice = display_units(d);
  const DisplayUnit *unit = &choice.units[choice.preferred];
  if (si_value != 0.0 && std::isfinite(si_value))
  {
    unit = &choice.units.back();
    for (const auto &u : choice.units)
      if (std::abs(si_value) / u.factor >= 0.9999995)
      {
        unit = &u;
        break;
      }
  }
  const std::string number = format_number(si_value / unit->factor);
  return unit->symbol[0] == '\0' ? number : number + " " + unit->symbol;
}

} // namespace magbrush
