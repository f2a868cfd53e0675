// `magbrush design gap|bias --target VALUE STUDY_DIR`: the varied value that reaches a target,
// read off a finished study with its standard error (design/study_inverse.h).
#include "app/design_study_command.h"

#include "coupling/units.h"
#include "design/study_inverse.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

struct StudyKind
{
  std::string key, quantity;
  Dimension x_dimension;
};

StudyKind kind_of(const std::string &mode)
{
  if (mode == "gap")
    return {"blades.doctor.gap", "dma_kg_per_m2", Dimension::length};
  return {"electric.bias", "tma_kg_per_m2", Dimension::voltage};
}

// "0.40kg/m2" as the sweep's tables write areal masses: "m2" read as "m^2". A quantity that is
// not a mass per area (--quantity released_fraction) is a plain number.
double target_value(const std::string &text, const std::string &quantity)
{
  if (quantity.find("kg_per_m2") == std::string::npos)
    return parse_quantity(text, Dimension::dimensionless);
  const std::string normalised = std::regex_replace(text, std::regex("m2$"), "m^2");
  return parse_quantity(normalised, Dimension::areal_mass, BareNumber::si);
}

// The table: --table, else the study's sweep_mean.csv (repeats' spread), else sweep_summary.csv.
std::string table_path(const cli::ParsedArguments &args)
{
  if (args.has("--table"))
    return args.value("--table");
  const fs::path dir = args.positional(1);
  if (fs::is_regular_file(dir))
    return dir.string();
  return fs::exists(dir / "sweep_mean.csv") ? (dir / "sweep_mean.csv").string() : (dir / "sweep_summary.csv").string();
}

// A gap in mm to 0.1 um, a bias in V to 0.1 V, anything else to 5 significant digits.
std::string shown(double si, Dimension d)
{
  char buf[64];
  if (d == Dimension::length)
    std::snprintf(buf, sizeof buf, "%.4f mm", si * 1e3);
  else if (d == Dimension::voltage)
    std::snprintf(buf, sizeof buf, "%.1f V", si);
  else
    std::snprintf(buf, sizeof buf, "%.5g", si);
  return buf;
}

} // namespace

int run_design_study(const cli::ParsedArguments &args, const std::string &mode)
{
  StudyKind kind = kind_of(mode);
  if (args.has("--key"))
    kind = {args.value("--key"), kind.quantity, Dimension::dimensionless};
  kind.quantity = args.value("--quantity", kind.quantity);
  if (!args.has("--target"))
    throw cli::UsageError("design " + mode + " needs --target VALUE (e.g. --target 0.40kg/m2)");
  const double target = target_value(args.value("--target"), kind.quantity);
  const std::string path = table_path(args);
  const StudyTable table = read_study_table(path, kind.key, kind.quantity);
  const std::string m = args.value("--method", "auto");
  const StudyAnswer a = invert_study(table, target,
                                     m == "line"        ? StudyAnswer::Method::line
                                     : m == "piecewise" ? StudyAnswer::Method::piecewise
                                                        : StudyAnswer::Method::automatic);
  std::cout << "magbrush design " << mode << ": " << kind.key << " for " << kind.quantity << " = "
            << args.value("--target") << " from " << path << " (" << table.points.size() << " points)\n";
  char buf[256];
  for (const auto &p : table.points)
  {
    std::snprintf(buf, sizeof buf, "  %-24s %14s   %.4g ± %.2g\n", p.label.c_str(), shown(p.x, kind.x_dimension).c_str(),
                  p.y, p.se);
    std::cout << buf;
  }
  for (const auto &n : table.notes)
    std::cout << "  note: " << n << "\n";
  std::cout << "\n" << kind.key << " = " << shown(a.x, kind.x_dimension) << " ± " << shown(a.se, kind.x_dimension)
            << " (one standard error; 95 % interval " << shown(a.x - 1.96 * a.se, kind.x_dimension) << " .. "
            << shown(a.x + 1.96 * a.se, kind.x_dimension) << ")\n  by " << a.how << "\n";
  if (!a.inside)
    std::cout << "\nThe target " << target << " lies OUTSIDE the study's range of " << kind.quantity
              << ": the answer above is an extrapolation of the line; extend the study (magbrush sweep "
              << (table.case_path.empty() ? "CASE" : table.case_path) << " --vary " << kind.key << "=...)\n";
  if (args.has("--tolerance"))
  {
    const double tolerance = kind.x_dimension == Dimension::dimensionless
                                 ? parse_quantity(args.value("--tolerance"), Dimension::dimensionless)
                                 : parse_quantity(args.value("--tolerance"), kind.x_dimension);
    if (1.96 * a.se > tolerance)
      std::cout << "\nThe 95 % interval (± " << shown(1.96 * a.se, kind.x_dimension) << ") is wider than the tolerance ± "
                << shown(tolerance, kind.x_dimension) << ": the point that narrows it most is the answer itself:\n"
                << "  magbrush sweep " << (table.case_path.empty() ? "CASE" : table.case_path) << " --vary " << kind.key
                << "=" << std::regex_replace(shown(a.x, kind.x_dimension), std::regex(" "), "") << "\n(then merge its row into the table and ask again)\n";
    else
      std::cout << "\nThe 95 % interval is within the tolerance ± " << shown(tolerance, kind.x_dimension) << ".\n";
  }
  return a.inside ? 0 : 3;
}

} // namespace magbrush
