// `magbrush design gap|bias --target VALUE STUDY_DIR`: the varied value that reaches a target,
// read off a finished study with its standard error (design/study_inverse.h). With
// --tolerance it also says whether the 95 % interval is narrow enough and, when it is not,
// which one extra point would narrow it most (design/study_refinement.h); with --refine it runs
// that point as a point of the study itself (app/study_extension.h), reads the study again and
// repeats, until the interval is within the tolerance, --max-points have run, or one more point
// would no longer help (the answer's error is then one run's: longer runs or repeats narrow it).
#include "app/design_study_command.h"

#include "app/study_extension.h"
#include "app/subcommand.h"
#include "common/child_process.h"
#include "case/units.h"
#include "design/study_inverse.h"
#include "design/study_refinement.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
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

// A varied key's dimension from its SI column's unit ("<key> [m]"): a length or a voltage is
// shown and given (--tolerance 1um) as such, anything else as a plain number.
Dimension dimension_of_column(const std::string &path, const std::string &key)
{
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#')
      break;
  if (line.find(key + " [m]") != std::string::npos)
    return Dimension::length;
  if (line.find(key + " [V]") != std::string::npos)
    return Dimension::voltage;
  return Dimension::dimensionless;
}

StudyAnswer::Method method_of(const cli::ParsedArguments &args)
{
  const std::string m = args.value("--method", "auto");
  return m == "line" ? StudyAnswer::Method::line
         : m == "piecewise" ? StudyAnswer::Method::piecewise
                            : StudyAnswer::Method::automatic;
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

// The inverse of the table as it stands, printed; returns it.
StudyAnswer answer_and_print(const cli::ParsedArguments &args, const std::string &mode, const StudyKind &kind,
                             double target, const std::string &path, StudyTable &table)
{
  table = read_study_table(path, kind.key, kind.quantity);
  const StudyAnswer a = invert_study(table, target, method_of(args));
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
  return a;
}

// The extra point's value as the sweep is given it ("0.4756mm", "-612.3V").
std::string value_text(double x, Dimension d)
{
  return std::regex_replace(shown(x, d), std::regex(" "), "");
}

} // namespace

int run_design_study(const cli::ParsedArguments &args, const std::string &mode)
{
  StudyKind kind = kind_of(mode);
  const std::string path = table_path(args);
  if (args.has("--key"))
    kind = {args.value("--key"), kind.quantity, dimension_of_column(path, args.value("--key"))};
  kind.quantity = args.value("--quantity", kind.quantity);
  if (!args.has("--target"))
    throw cli::UsageError("design " + mode + " needs --target VALUE (e.g. --target 0.40kg/m2)");
  const bool refine = args.has("--refine");
  if (refine && !args.has("--tolerance"))
    throw cli::UsageError("--refine runs points until the 95 % interval is within --tolerance: give it");
  if (refine && args.has("--table"))
    throw cli::UsageError("--refine extends the study in STUDY_DIR; it cannot extend a --table");
  const double target = target_value(args.value("--target"), kind.quantity);
  const long max_points = args.whole_number("--max-points", 3, 1, 100);
  std::vector<std::string> stage_options;
  for (const char *option : {"--threads", "--skip"})
    if (args.has(option))
      stage_options.insert(stage_options.end(), {option, args.value(option)});
  for (long added = 0;; ++added)
  {
    StudyTable table;
    const StudyAnswer a = answer_and_print(args, mode, kind, target, path, table);
    if (!args.has("--tolerance"))
      return a.inside ? 0 : 3;
    if (!a.inside)
      return 3;
    const double tolerance = kind.x_dimension == Dimension::dimensionless
                                 ? parse_quantity(args.value("--tolerance"), Dimension::dimensionless)
                                 : parse_quantity(args.value("--tolerance"), kind.x_dimension);
    if (1.96 * a.se <= tolerance)
    {
      std::cout << "\nThe 95 % interval is within the tolerance ± " << shown(tolerance, kind.x_dimension)
                << (added > 0 ? " after " + std::to_string(added) + " extra point(s)" : "") << ".\n";
      return 0;
    }
    const RefinementPlan next = plan_refinement(table, target, method_of(args));
    const std::string value = value_text(next.x, kind.x_dimension);
    std::cout << "\nThe 95 % interval (± " << shown(1.96 * a.se, kind.x_dimension)
              << ") is wider than the tolerance ± " << shown(tolerance, kind.x_dimension)
              << ". The point that narrows it most: " << kind.key << " = " << value << " (predicted "
              << kind.quantity << " " << next.predicted_y << " ± " << next.predicted_se << "), the answer's ± "
              << shown(next.se_now, kind.x_dimension) << " → ± " << shown(next.se_after, kind.x_dimension) << "\n";
    if (!refine)
    {
      std::cout << "  (run it with --refine, or by hand: magbrush sweep "
                << (table.case_path.empty() ? "CASE" : table.case_path) << " --vary " << kind.key << "=" << value
                << " ...)\n";
      return 4;
    }
    if (added >= max_points)
    {
      std::cout << "--refine: " << added << " extra point(s) run (--max-points " << max_points
                << "); the interval is still wider than the tolerance.\n";
      return 4;
    }
    if (next.gain() < 0.1)
    {
      std::cout << "--refine: one more point would narrow the answer by " << std::lround(100 * next.gain())
                << " % only: the answer's error is set by the runs' own errors; longer runs or --repeats narrow it, more points of this length hardly do.\n";
      return 4;
    }
    const FinishedSweep sweep = read_finished_sweep(fs::path(path).parent_path(), kind.key);
    const std::string magbrush = (fs::path(executable_dir()) / "magbrush").string();
    std::cout << "\n--refine: running " << kind.key << " = " << value << " as a point of " << sweep.dir.string()
              << "/" << std::endl;
    for (auto words : extended_sweep_commands(sweep, value, stage_options))
    {
      std::string shown_words = "magbrush";
      for (const auto &w : words)
        shown_words += " " + w;
      std::cout << "  " << shown_words << std::endl;
      words.insert(words.begin(), magbrush);
      const int rc = run_program(words);
      if (rc != 0)
      {
        std::cerr << "magbrush design " << mode << " --refine: the extra point failed (exit " << rc << ")\n";
        return 1;
      }
    }
    std::cout << "\n";
  }
}

} // namespace magbrush
