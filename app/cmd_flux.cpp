// `magbrush flux CASE [--measured SCAN.csv] [--fit] ...`: the sleeve flux profile of a case
// against a gaussmeter scan, and calibration of the pole model to the scan.
//
// The steps, as run() reads:
//   1. load the case and decide the probe radius (field.probe_radius, 0 = sleeve radius);
//   2. the computed profile: the FEM's when magbrush-field has written one for this radius,
//      otherwise the exact multipole ring (which one is always said);
//   3. read the scan, compare (RMS/max errors, per-pole peaks), write the residuals and plot;
//   4. --fit: Levenberg–Marquardt on the exact ring (one shape factor for all poles or one
//      each, chosen by an F-test), parameters with uncertainties, the residual against the
//      noise estimated from the scan, the comparison with the scan rotated by the fitted
//      encoder offset, the fitted case file (which records that offset as the scan's angular
//      origin), and "the FEM as the final check" when magbrush-field is available.
// With --compare OTHER_CASE there is no scan: two cases' profiles are overlaid and each pole's
// peak shift tabulated instead (app/flux_case_comparison.h).
#include "app/subcommand.h"
#include "app/flux_case_comparison.h"
#include "app/flux_tools.h"

#include "calibration/flux_compare.h"
#include "calibration/flux_scan.h"
#include "calibration/pole_fit.h"
#include "common/atomic_file.h"
#include "common/child_process.h"
#include "case/case_hash.h"
#include "case/case_parser.h"
#include "fields/field_files.h"
#include "fields/field_grid.h"
#include "fields/multipole_ring.h"
#include "case/units.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;
constexpr double to_deg = 180.0 / M_PI;

// The options, declared once: the parser and `magbrush run` read them (common/command_line.h).
const cli::CommandSpec &flux_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush flux";
    s.usage = "magbrush flux CASE [--measured SCAN.csv] [-o DIR] [--set key=value ...] [options]\n"
              "       magbrush flux CASE --compare OTHER_CASE [--compare-set key=value ...] [--set ...] [-o DIR]";
    s.description = R"(Compares the sleeve flux profile of a case with a gaussmeter scan, and with --fit calibrates
the Gaussian pole model (strengths, angles, shape factors, encoder offset) to it.

The computed profile is taken at field.probe_radius (0 = the sleeve radius): from the finite-
element field (<field.output_dir>/<case>_profile_probe.csv, written by `magbrush field`) when
it exists for that radius and its stored field matches the case as it is now (else it is
called stale, with the key that differs), otherwise from the exact multipole-ring solution.

Scan (CSV): columns angle, Bn[, Bt] in any order (names like angle_deg/theta, Bn/B_n/Br,
Bt/B_t/Btheta), units in the header (angle_deg, Bn_mT, "Bn [G]") or given below, '#' comments.
Without --measured the case's measured_flux_file is used; without either only the computed
profile is written.

With --compare OTHER_CASE: no scan; the profiles of the two cases overlaid instead, each pole's
peak in both (poles matched by name) and how far it moved (angle, Bn), B = OTHER_CASE against
A = CASE. --set applies to both, --compare-set to OTHER_CASE only, so a variant of one case is
`--compare CASE --compare-set key=value`. Both profiles come from the same source: the FEM's
when `magbrush field` has stored one for each case as it is now, else the exact ring for both.
)";
    s.positionals = {{"CASE", "the case file"}};
    s.options = {
        {"--measured", {}, "FILE", "the gaussmeter scan"},
        {"--output", {"-o"}, "DIR", "output directory (default: <output.directory>/flux)", false, {},
         /*for_pipeline=*/false},
        cli::set_option("field.probe_radius=10mm"),
        {"--angle-unit", {}, "deg|rad", "unit of the scan's angle column (overrides the header)"},
        {"--field-unit", {}, "T|mT|G|kG", "unit of the scan's Bn/Bt columns (overrides the header)"},
        {"--angle-offset", {}, "ANGLE",
         "roller angle = scan angle + ANGLE (e.g. 2.5deg); default: the case's\n"
         "measured_flux_angle_origin (which --fit writes into the fitted case)"},
        {"--clockwise", {}, "", "the scan's angle runs clockwise (Bt is then negated too)"},
        {"--flip-bt", {}, "", "the probe's Bt is positive clockwise: negate it"},
        {"--source", {}, "auto|ring|fem",
         "computed profile from the FEM if present (auto), the exact ring, or\nthe FEM only (error if missing)",
         false, {"auto", "ring", "fem"}},
        {"--fit", {}, "", "fit the pole model to the scan; writes <case>_fitted.yaml in DIR"},
        {"--fit-shape", {}, "auto|shared|per-pole|fixed",
         "shape factors α: auto (default) fits one for all and one per pole and\n"
         "keeps per-pole when an F-test finds it significantly better (p < 0.001);\n"
         "or one for all, one per pole, held at the case's values",
         false, {"auto", "shared", "per-pole", "per_pole", "fixed"}},
        {"--no-offset", {}, "", "do not fit an encoder offset (every pole angle free)"},
        {"--bn-only", {}, "", "fit Bn only (ignore Bt)"},
        {"--no-fem-check", {}, "", "skip running magbrush-field on the fitted case"},
        {"--no-plot", {}, "",
         "do not call tools/plot_flux.py (the plot needs python3 with\nmatplotlib; $MAGBRUSH_PYTHON picks the interpreter)"},
        {"--harmonics", {}, "N", "number of Fourier harmonics (default: from the decay of the series)"},
        {"--compare", {}, "OTHER_CASE", "overlay this case's sleeve flux on CASE's, with each pole's peak shift",
         false, {}, /*for_pipeline=*/false},
        {"--compare-set", {}, "key=value",
         "override a key of OTHER_CASE only (repeatable), e.g.\n--compare-set roller.poles.S1.angle=5deg",
         /*repeatable=*/true, {}, /*for_pipeline=*/false}};
    s.epilog = R"(Outputs in DIR: flux_profile.csv (computed, 0.25 deg), flux_residuals.csv, flux_overlay.png,
and with --fit: flux_fit_residuals.csv, <case>_fitted.yaml, flux_fit.txt.
With --compare (DIR default: <CASE's run folder>/flux/compare_<OTHER's run folder>):
flux_compare.csv (both profiles and B - A), flux_compare_peaks.csv, flux_compare.png.
)";
    s.examples = {{"magbrush flux cases/kawamoto_nip.yaml --measured cases/data/sleeve_profile_example.csv --fit",
                   "compare a gaussmeter scan with the computed flux and fit the poles to it"},
                  {"magbrush flux cases/kawamoto_nip_fed.yaml --compare cases/kawamoto_nip_fed.yaml "
                   "--compare-set roller.poles.S1.angle=5deg",
                   "the development pole moved 5 deg downstream: both profiles and every pole's peak shift"}};
    s.exit_status = "0 done, 1 bad input (message says what and how to fix), 2 bad usage.";
    return s;
  }();
  return spec;
}

struct FluxOptions
{
  std::string case_path, measured, output_dir;
  std::vector<std::string> overrides;
  ScanReadOptions scan;
  std::string source = "auto";
  bool fit = false, no_fem_check = false, no_plot = false;
  PoleFitOptions fit_options;
  bool angle_offset_given = false; // --angle-offset (else the case's measured_flux_angle_origin)
  int harmonics = 0;
};

// What the parsed command line asks for, in the terms of the steps below.
FluxOptions flux_options(const cli::ParsedArguments &args)
{
  FluxOptions o;
  o.case_path = args.positional(0);
  o.measured = args.value("--measured");
  o.output_dir = args.value("--output");
  o.overrides = args.values("--set");
  o.scan.angle_unit = args.value("--angle-unit", o.scan.angle_unit);
  o.scan.field_unit = args.value("--field-unit", o.scan.field_unit);
  o.angle_offset_given = args.has("--angle-offset");
  if (o.angle_offset_given)
    o.scan.angle_offset = parse_quantity(args.value("--angle-offset"), Dimension::angle);
  o.scan.clockwise = args.has("--clockwise");
  o.scan.flip_tangential = args.has("--flip-bt");
  o.source = args.value("--source", "auto");
  o.fit = args.has("--fit");
  const std::string shape = args.value("--fit-shape");
  if (shape == "auto")
    o.fit_options.shape = PoleFitOptions::Shape::automatic;
  else if (shape == "shared")
    o.fit_options.shape = PoleFitOptions::Shape::shared;
  else if (shape == "per-pole" || shape == "per_pole")
    o.fit_options.shape = PoleFitOptions::Shape::per_pole;
  else if (shape == "fixed")
    o.fit_options.shape = PoleFitOptions::Shape::fixed;
  if (args.has("--no-offset"))
    o.fit_options.fit_offset = false;
  if (args.has("--bn-only"))
    o.fit_options.use_tangential = false;
  o.no_fem_check = args.has("--no-fem-check");
  o.no_plot = args.has("--no-plot");
  o.harmonics = static_cast<int>(args.whole_number("--harmonics", 0, 1, 4096));
  if (o.harmonics > 0)
    o.fit_options.harmonics = o.harmonics;
  return o;
}

// ---------------------------------------------------------------------------------------

void write_profile_csv(const std::string &path, const Case &c, double r,
                       const ComputedProfile &p, const std::vector<double> &angles)
{
  std::ostringstream out;
  out << "# Computed sleeve flux profile of case '" << c.name << "' at radius " << r * 1e3
      << " mm, from the " << p.source << ".\n"
      << "# angle counter-clockwise from +x; Bn positive outward, Bt positive counter-clockwise.\n"
      << "angle_deg,Bn_mT,Bt_mT\n";
  char buf[128];
  for (size_t k = 0; k < angles.size(); ++k)
  {
    std::snprintf(buf, sizeof buf, "%.4f,%.6f,%.6f\n", angles[k] * to_deg, p.Bn[k] * 1e3,
                  p.Bt[k] * 1e3);
    out << buf;
  }
  write_text_atomically(path, out.str());
}

void print_comparison(const FluxComparison &c, const std::string &title)
{
  std::cout << title << "\n" << format_errors(c) << "\n" << format_peaks(c) << "\n";
}

// ---------------------------------------------------------------------------------------
// The fitted case file: the user's YAML with roller.poles replaced (comments are lost).

std::string fitted_case_text(const Case &c, const FluxOptions &o, const PoleFitResult &fit,
                             double scan_origin, const std::string &scan_path,
                             const std::string &fitted_name)
{
  YAML::Node root = YAML::LoadFile(c.source_file);
  for (const auto &ov : o.overrides)
    apply_override(root, ov);
  root["name"] = fitted_name;
  root["measured_flux_file"] = fs::absolute(scan_path).lexically_normal().string();
  std::vector<Pole> fitted;
  for (const auto &p : fit.poles)
    fitted.push_back(p.pole);
  const YAML::Node poles = poles_yaml(fitted);
  root["roller"]["poles"] = poles;
  if (fit.shape == PoleFitOptions::Shape::shared)
    root["roller"]["shape_factor"] = fixed(fit.poles[0].pole.shape_factor, 4) + " rad^-2";
  // The scan's angular origin as the fit found it: the one it was read with plus the fitted
  // offset, so that every later comparison with this scan lines up with the fitted poles.
  root["measured_flux_angle_origin"] = fixed(scan_origin * to_deg, 4) + " deg";

  std::ostringstream out;
  std::time_t now = std::time(nullptr);
  char stamp[64];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  out << "# " << fitted_name << ": case '" << c.name << "' (" << c.source_file
      << ") with the poles fitted by\n#   magbrush flux --fit to the scan " << scan_path << " ("
      << stamp << ").\n"
      << "# Residual RMS " << fixed(fit.rms * 1e3, 3) << " mT over " << fit.samples
      << " values; encoder offset " << fixed(fit.offset * to_deg, 4) << " ± "
      << fixed(fit.offset_sigma * to_deg, 4)
      << " deg, included in measured_flux_angle_origin (roller angle = scan angle + origin).\n"
      << "# Comments of the original file are not carried over.\n";
  YAML::Emitter emitter;
  emitter << root;
  out << emitter.c_str() << "\n";
  return out.str();
}

std::string fit_report(const PoleFitResult &fit, const FluxOptions &o)
{
  std::ostringstream out;
  char buf[256];
  out << "Pole fit (Levenberg–Marquardt on the exact ring, " << fit.harmonics << " harmonics): "
      << fit.status << "\n"
      << "  " << fit.samples << " residuals, " << fit.parameters << " parameters, "
      << fit.iterations << " iterations, " << fit.evaluations << " evaluations\n"
      << "  residual RMS " << fixed(fit.rms * 1e3, 4) << " mT (Bn " << fixed(fit.rms_Bn * 1e3, 4)
      << ", Bt " << fixed(fit.rms_Bt * 1e3, 4) << "), initial guess " << fixed(fit.initial_rms * 1e3, 3)
      << " mT\n"
      << "  noise estimated from the scan " << fixed(fit.noise_rms * 1e3, 4) << " mT (Bn "
      << fixed(fit.noise.Bn * 1e3, 4) << ", Bt " << fixed(fit.noise.Bt * 1e3, 4)
      << "; each sample against the cubic through its two neighbours on either side): residual / "
         "noise = "
      << fixed(fit.noise_rms > 0 ? fit.rms / fit.noise_rms : 0.0, 2) << "\n"
      << "  shape factors: " << shape_name(fit.shape)
      << (fit.shape_selection.automatic ? " (chosen: " + fit.shape_selection.reason + ")"
                                        : std::string(" (as asked)"))
      << "\n";
  if (o.fit_options.fit_offset)
    out << "  encoder offset " << fixed(fit.offset * to_deg, 4) << " ± "
        << fixed(fit.offset_sigma * to_deg, 4)
        << " deg (roller angle = scan angle + offset; defined so that the pole angles deviate "
           "from the case's by zero on average)\n";
  out << "\n  pole   angle [deg]            strength [kA/m]        shape α [1/rad²]     "
         "(initial: angle, strength)\n";
  for (const auto &p : fit.poles)
  {
    std::snprintf(buf, sizeof buf,
                  "  %-5s  %8.3f ± %-8.3f   %9.2f ± %-8.2f   %7.3f ± %-7.3f    (%.2f, %.1f)\n",
                  p.pole.name.c_str(), p.pole.angle * to_deg, p.angle_sigma * to_deg,
                  p.pole.strength * 1e-3, p.strength_sigma * 1e-3, p.pole.shape_factor,
                  p.shape_sigma, p.initial.angle * to_deg, p.initial.strength * 1e-3);
    out << buf;
  }
  out << "  (± one standard error from the Jacobian at the optimum, s² = RSS/(m − p))\n";
  for (const auto &n : fit.notes)
    out << "  note: " << n << "\n";
  const std::string warning = residual_warning(fit);
  if (!warning.empty())
    out << "\nwarning: " << warning << "\n";
  return out.str();
}

// "The FEM as the final check": magbrush-field on the fitted case, its probe profile against
// the scan, and the FEM against the exact ring. Says why when it cannot be done.
// `scan` is in the fitted case's roller frame (rotated by the fitted encoder offset).
void fem_check(const std::string &fitted_case, const FluxScan &scan, const std::string &dir)
{
  const fs::path field_exe = fs::path(executable_dir()) / "magbrush-field";
  if (!fs::exists(field_exe))
  {
    std::cout << "FEM check skipped: " << field_exe.string()
              << " is not built (build the magbrush-field target to check the fit by FEM)\n";
    return;
  }
  std::cout << "FEM check: running magbrush-field on " << fitted_case << " ...\n" << std::flush;
  const std::string log = dir + "/flux_fem_check.log";
  const std::vector<std::string> fields_here = {"field.output_dir=" + dir + "/fem_check_fields"};
  const std::string failure = run_magnetic_field_solver(fitted_case, log, fields_here);
  if (!failure.empty())
  {
    std::cout << "FEM check failed: " << failure << "\n";
    return;
  }
  const Case fitted = load_case(fitted_case, fields_here);
  const double r = probe_radius_of(fitted);
  std::string why;
  const std::string path = fem_profile_path(fitted, r, why);
  if (path.empty())
  {
    std::cout << "FEM check: no profile to compare: " << why << "\n";
    return;
  }
  const MultipoleRing ring(*fitted.roller);
  const ComputedProfile fem = computed_at(scan.angle, ring, r, path);
  const FluxComparison c = compare_flux(scan, fem.Bn, fem.Bt, fitted.roller->poles);
  print_comparison(c, "FEM of the fitted case against the scan (" + fem.source + "):");
  write_residuals_csv(dir + "/flux_fem_check_residuals.csv", c);
  // And the FEM against the exact ring it should reproduce (the discretisation error).
  std::vector<double> Bn, Bt;
  ring.profile(r, scan.angle, Bn, Bt);
  double diff = 0.0, peak = 0.0;
  for (size_t k = 0; k < Bn.size(); ++k)
  {
    diff = std::max(diff, std::hypot(fem.Bn[k] - Bn[k], fem.Bt[k] - Bt[k]));
    peak = std::max(peak, std::hypot(Bn[k], Bt[k]));
  }
  std::cout << "  FEM against the exact ring of the fitted case: max |ΔB| = " << fixed(diff * 1e3, 3)
            << " mT (" << scientific(diff / peak) << " of the peak |B|)\n"
            << "  (magbrush-field log: " << log << ")\n";
}

// ---------------------------------------------------------------------------------------

// The command, step by step; run() reads like the procedure in the header comment.
class FluxCommand
{
public:
  explicit FluxCommand(const FluxOptions &options) : o_(options) {}

  int run()
  {
    load_case_and_exact_ring();
    write_computed_profile();
    if (!read_scan())
      return report_computed_peaks();
    compare_with_scan();
    if (o_.fit)
    {
      fit_poles_to_scan();
      write_fitted_case();
    }
    plot_overlay();
    if (o_.fit)
      check_fit_by_fem();
    return 0;
  }

private:
  FluxOptions o_;
  Case case_;
  double probe_radius_ = 0.0;
  MultipoleRing::Options ring_options_;
  std::optional<MultipoleRing> ring_;
  std::string dir_, fem_path_, why_not_fem_ = "--source ring";
  std::vector<double> grid_;           // 0.25° profile grid [rad]
  ComputedProfile on_grid_;
  std::string scan_path_;
  std::optional<FluxScan> scan_;
  std::string residuals_, fit_residuals_, fitted_case_;
  std::optional<PoleFitResult> fit_;
  std::optional<FluxScan> aligned_scan_; // the scan rotated by the fitted encoder offset

  // 1. The case, the probe radius, the exact ring.
  void load_case_and_exact_ring()
  {
    case_ = load_case(o_.case_path, o_.overrides);
    probe_radius_ = probe_radius_of(case_);
    choose_scan_origin();
    ring_options_.harmonics = o_.harmonics;
    ring_.emplace(*case_.roller, ring_options_);
    dir_ = o_.output_dir.empty() ? case_.output.directory + "/flux" : o_.output_dir;
    fs::create_directories(dir_);
    std::cout << "magbrush flux: case '" << case_.name << "', probe radius "
              << fixed(probe_radius_ * 1e3, 3) << " mm (magnet "
              << fixed(case_.roller->magnet_radius * 1e3, 3) << " mm), "
              << case_.roller->poles.size() << " poles\n"
              << "  exact ring: " << ring_->harmonic_count() << " harmonics"
              << (o_.harmonics ? " (as asked)"
                  : ring_->harmonic_choice().capped
                      ? " (capped: wide poles, α ≲ 3, have a slope kink at the back of the roller "
                        "and a slowly decaying series; outside the magnet the field still converges "
                        "geometrically)"
                      : " (chosen from the decay: every coefficient beyond is below " +
                            scientific(std::max(ring_->harmonic_choice().tail, 1e-16)) +
                            " of the largest)")
              << "\n";
  }

  // The scan's angular origin: --angle-offset when given, else the case's
  // measured_flux_angle_origin (a fitted case carries the encoder offset its fit found).
  void choose_scan_origin()
  {
    if (!o_.angle_offset_given)
      o_.scan.angle_offset = case_.measured_flux_angle_origin;
    else if (case_.measured_flux_angle_origin != 0.0)
      std::cout << "  note: --angle-offset " << fixed(o_.scan.angle_offset * to_deg, 4)
                << " deg replaces the case's measured_flux_angle_origin "
                << fixed(case_.measured_flux_angle_origin * to_deg, 4) << " deg\n";
  }

  // 2. The computed profile: the FEM's if there is one for this radius, else the exact ring.
  void write_computed_profile()
  {
    fem_path_ = o_.source == "ring" ? "" : fem_profile_path(case_, probe_radius_, why_not_fem_);
    if (o_.source == "fem" && fem_path_.empty())
      throw std::invalid_argument("--source fem: " + why_not_fem_);
    for (int k = 0; k < 1440; ++k)
      grid_.push_back(k * 0.25 / to_deg);
    on_grid_ = computed_at(grid_, *ring_, probe_radius_, fem_path_);
    std::cout << "  computed profile: " << on_grid_.source << "\n";
    if (fem_path_.empty())
      std::cout << "  (" << why_not_fem_ << ")\n";
    write_profile_csv(dir_ + "/flux_profile.csv", case_, probe_radius_, on_grid_, grid_);
    std::cout << "  profile     " << dir_ << "/flux_profile.csv\n";
  }

  // 3. The scan (false when none is given).
  bool read_scan()
  {
    scan_path_ = o_.measured.empty() ? case_.measured_flux_file : o_.measured;
    if (scan_path_.empty())
    {
      if (o_.fit)
        throw std::invalid_argument("--fit needs a scan: give --measured FILE.csv (or set "
                                    "measured_flux_file in the case)");
      return false;
    }
    scan_ = read_flux_scan(scan_path_, o_.scan);
    std::cout << "  scan: " << scan_path_ << ": " << scan_->size() << " points, angle in "
              << scan_->angle_unit << ", field in " << scan_->field_unit
              << (scan_->has_tangential() ? ", Bn and Bt" : ", Bn only") << "\n";
    for (const auto &n : scan_->notes)
      std::cout << "  note: " << n << "\n";
    if (o_.scan.angle_offset != 0.0)
      std::cout << "  scan angular origin " << fixed(o_.scan.angle_offset * to_deg, 4)
                << " deg (roller angle = scan angle + origin)\n";
    return true;
  }

  int report_computed_peaks()
  {
    const auto peaks = find_pole_peaks(case_.roller->poles, grid_, on_grid_.Bn);
    std::cout << "\nNo scan given (--measured or measured_flux_file): computed peaks only.\n"
              << "  pole   angle [deg]   Bn peak [mT]\n";
    for (size_t i = 0; i < peaks.size(); ++i)
      std::cout << "  " << case_.roller->poles[i].name << "    "
                << (peaks[i].found ? fixed(peaks[i].angle * to_deg, 2) + "      " +
                                         fixed(peaks[i].value * 1e3, 2)
                                   : std::string("(no peak)"))
                << "\n";
    return 0;
  }

  // 4. Errors and peaks side by side, residuals.
  void compare_with_scan()
  {
    const ComputedProfile computed = computed_at(scan_->angle, *ring_, probe_radius_, fem_path_);
    const FluxComparison c = compare_flux(*scan_, computed.Bn, computed.Bt, case_.roller->poles);
    std::cout << "\n";
    print_comparison(c, "Scan against the " + computed.source + ":");
    residuals_ = dir_ + "/flux_residuals.csv";
    write_residuals_csv(residuals_, c);
    std::cout << "  residuals   " << residuals_ << "\n";
  }

  // 5. Levenberg–Marquardt on the exact ring, and the fitted model against the scan.
  void fit_poles_to_scan()
  {
    fit_ = fit_poles(*case_.roller, *scan_, probe_radius_, o_.fit_options);
    std::cout << "\n" << fit_report(*fit_, o_) << "\n";
    if (!fit_->converged)
      std::cout << "warning: the fit did not converge; the parameters above are the last iterate\n";
    // From here on the scan is seen as the fit saw it: rotated by the fitted encoder offset.
    aligned_scan_ = rotated_scan(*scan_, fit_->offset);
    const FluxComparison c =
        compare_with_fitted_model(*scan_, *fit_, probe_radius_, ring_options_);
    print_comparison(c, "Scan against the fitted pole model (exact ring, scan rotated by the "
                        "fitted encoder offset " + fixed(fit_->offset * to_deg, 4) + " deg):");
    fit_residuals_ = dir_ + "/flux_fit_residuals.csv";
    write_residuals_csv(fit_residuals_, c);
    std::cout << "  residuals   " << fit_residuals_ << "\n";
  }

  // 6. <case>_fitted.yaml (checked by loading it back) and the fit report.
  void write_fitted_case()
  {
    const std::string stem = fs::path(case_.source_file).stem().string();
    fitted_case_ = dir_ + "/" + stem + "_fitted.yaml";
    const double origin = std::remainder(o_.scan.angle_offset + fit_->offset, 2.0 * M_PI);
    write_text_atomically(fitted_case_, fitted_case_text(case_, o_, *fit_, origin, scan_path_,
                                                         case_.name + "_fitted"));
    write_text_atomically(dir_ + "/flux_fit.txt", fit_report(*fit_, o_));
    try
    {
      load_case(fitted_case_);
    }
    catch (const std::exception &e)
    {
      throw std::runtime_error("internal error: the fitted case " + fitted_case_ +
                               " does not load: " + e.what());
    }
    std::cout << "  fitted case " << fitted_case_ << " (measured_flux_angle_origin "
              << fixed(origin * to_deg, 4) << " deg)\n  fit report  " << dir_ << "/flux_fit.txt\n";
  }

  void plot_overlay()
  {
    if (o_.no_plot)
      return;
    const std::string title = "Case '" + case_.name + "'" + (fit_ ? " and its fitted poles" : "") +
                              " against " + scan_path_;
    std::vector<std::string> arguments = {"--residuals", residuals_};
    if (fit_)
      arguments.insert(arguments.end(), {"--fitted", fit_residuals_});
    arguments.insert(arguments.end(), {"--title", title, "--label",
                                       fem_path_.empty() ? "exact ring" : "FEM", "-o", dir_ + "/flux_overlay.png"});
    run_plot_script("plot_flux.py", arguments, dir_ + "/flux_overlay.png");
  }

  // 7. "The FEM as the final check".
  void check_fit_by_fem()
  {
    if (o_.no_fem_check)
      std::cout << "FEM check skipped (--no-fem-check)\n";
    else
      fem_check(fitted_case_, *aligned_scan_, dir_);
  }
};

// --compare: two cases' profiles instead of a case against a scan (app/flux_case_comparison.h).
int compare_two_cases(const cli::ParsedArguments &args)
{
  for (const char *scan_option : {"--measured", "--fit", "--fit-shape", "--no-offset", "--bn-only", "--no-fem-check",
                                  "--angle-offset", "--angle-unit", "--field-unit", "--clockwise", "--flip-bt"})
    if (args.has(scan_option))
      throw cli::UsageError(std::string(scan_option) +
                            " is for a gaussmeter scan; --compare overlays two cases' computed profiles: give one or "
                            "the other");
  FluxCaseComparisonOptions o;
  o.case_path = args.positional(0);
  o.other_path = args.value("--compare");
  o.overrides = args.values("--set");
  o.other_overrides = args.values("--compare-set");
  o.output_dir = args.value("--output");
  o.source = args.value("--source", "auto");
  o.harmonics = static_cast<int>(args.whole_number("--harmonics", 0, 1, 4096));
  o.no_plot = args.has("--no-plot");
  return compare_case_fluxes(o);
}

int flux(const cli::ParsedArguments &args)
{
  if (args.has("--compare"))
    return compare_two_cases(args);
  if (args.has("--compare-set"))
    throw cli::UsageError("--compare-set changes the case given with --compare: add --compare OTHER_CASE (it may "
                          "be CASE itself)");
  return FluxCommand(flux_options(args)).run();
}

int run_flux(const std::vector<std::string> &args)
{
  return cli::run_command(flux_command_line(), {args.begin() + 1, args.end()}, flux);
}

const bool registered = register_subcommand(
    {"flux", "compare the sleeve flux with a gaussmeter scan; --fit calibrates the poles",
     run_flux, flux_command_line, 50});

} // namespace
} // namespace magbrush
