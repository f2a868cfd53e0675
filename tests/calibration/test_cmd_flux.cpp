// End-to-end tests of `magbrush flux` (app/cmd_flux.cpp), run as a user would:
//  * --fit on the example scan recovers its header's poles in the written case file;
//  * --fit on a synthetic scan written here (gauss, radians, other column names, an encoder
//    offset, noise) recovers the generating poles and offset;
//  * the fitted case carries the fitted encoder offset (measured_flux_angle_origin) and later
//    comparisons apply it;
//  * a finite-element profile in field.output_dir is used when present;
//  * bad input: unreadable scan, bad cell, probe radius inside the magnet, --fit without a
//    scan, unknown option — exit status and message; a missing python only warns.
#include "case/case_parser.h"
#include "fields/field_grid.h"
#include "fields/multipole_ring.h"
#include "tests/calibration/test_support.h"
#include "tests/csv_columns.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace magbrush;
using namespace magbrush::flux_test;
namespace fs = std::filesystem;

namespace {

struct CommandResult
{
  int status = -1;
  std::string output; // stdout and stderr
};

CommandResult run_magbrush(const std::string &arguments, const std::string &environment = "")
{
  const std::string cmd = environment + " " + std::string(MAGBRUSH_BINARY_DIR) +
                          "/bin/magbrush flux " + arguments + " 2>&1";
  CommandResult r;
  FILE *pipe = popen(cmd.c_str(), "r");
  if (!pipe)
    return r;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    r.output.append(buffer.data(), n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

// RMS of a CSV column of numbers.
double rms(const std::vector<std::string> &column)
{
  double sum = 0.0;
  for (const auto &v : column)
    sum += std::stod(v) * std::stod(v);
  return column.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(column.size()));
}

// The written files of a fit on the example scan (360 samples, 1° apart) read back: each
// residual is measured − computed; the design profile (flux_profile.csv, 0.25° steps) is the
// "computed" column before the fit; the fit lowers the residual to the scan's noise (about
// 0.4 mT) from the design's ~7 mT; flux_fit.txt reports the RMS of its residual file.
void expect_flux_outputs_consistent(const fs::path &out)
{
  using magbrush::testing::read_csv_columns;
  const auto before = read_csv_columns(out / "flux_residuals.csv"), after = read_csv_columns(out / "flux_fit_residuals.csv");
  const auto profile = read_csv_columns(out / "flux_profile.csv");
  for (const auto *t : {&before, &after})
  {
    ASSERT_EQ(t->count("Bn_residual_mT"), 1u);
    ASSERT_EQ(t->at("angle_deg").size(), 360u);
    for (std::size_t k = 0; k < t->at("angle_deg").size(); ++k)
      for (const char *c : {"Bn", "Bt"})
      {
        const std::string b(c);
        EXPECT_NEAR(std::stod(t->at(b + "_residual_mT")[k]),
                    std::stod(t->at(b + "_measured_mT")[k]) - std::stod(t->at(b + "_computed_mT")[k]),
                    6e-4) // printed to 6 significant digits: 5e-4 at 100 mT
          << b << " row " << k;
      }
  }
  ASSERT_EQ(profile.at("angle_deg").size(), 1440u);
  for (std::size_t k = 0; k < 360; ++k) // scan angles 0, 1, 2, ... ° = profile rows 0, 4, 8, ...
  {
    EXPECT_NEAR(std::stod(profile.at("angle_deg")[4 * k]), std::stod(before.at("angle_deg")[k]), 1e-9);
    EXPECT_NEAR(std::stod(profile.at("Bn_mT")[4 * k]), std::stod(before.at("Bn_computed_mT")[k]), 6e-4) << k;
    EXPECT_NEAR(std::stod(profile.at("Bt_mT")[4 * k]), std::stod(before.at("Bt_computed_mT")[k]), 6e-4) << k;
  }
  const double rms_before = rms(before.at("Bn_residual_mT")), rms_after = rms(after.at("Bn_residual_mT"));
  EXPECT_GT(rms_before, 3.0);
  EXPECT_LT(rms_after, 0.5);
  std::ifstream in(out / "flux_fit.txt");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(contains(text, "converged")) << text;
  const auto at = text.find("(Bn ");
  ASSERT_NE(at, std::string::npos) << text;
  EXPECT_NEAR(std::stod(text.substr(at + 4)), rms_after, 1e-4 + 1e-3 * rms_after)
    << "flux_fit.txt does not report the residual file's Bn RMS:\n" << text;
}

// A scratch directory per test, private to this process.
fs::path scratch(const std::string &name) { return magbrush::testing::test_temp_dir("flux_" + name); }

// The case of the example roller with a design layout to start the fit from (the header's
// angles deviate from these by zero on average, so the fitted encoder offset is zero).
fs::path write_case(const fs::path &dir)
{
  const fs::path path = dir / "example_roller.yaml";
  std::ofstream(path) << R"(# The roller of cases/data/sleeve_profile_example.csv, design values.
name: example_roller
scene: roller
roller:
  shaft_radius: 3 mm
  shaft_mu_r: 1e12             # ideal iron
  magnet_radius: 9.3 mm
  magnet_mu_r: 1
  shape_factor: 10 rad^-2
  poles:
    - {name: S1, angle: 0 deg, strength: -300 kA/m}
    - {name: N1, angle: 70 deg, strength: 150 kA/m}
    - {name: S2, angle: 145 deg, strength: -150 kA/m}
    - {name: S3, angle: 215 deg, strength: -150 kA/m}
    - {name: N2, angle: 290 deg, strength: 150 kA/m}
sleeve:
  radius: 10 mm
  thickness: 0.3 mm
)" << "field:\n  output_dir: " << (dir / "fields").string() << "   # this test's own\n";
  return path;
}

double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

void expect_poles_near(const Roller &fitted, const Roller &truth, double angle_tol,
                       double strength_tol, double shape_tol)
{
  ASSERT_EQ(fitted.poles.size(), truth.poles.size());
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    const Pole &f = fitted.poles[i], &t = truth.poles[i];
    EXPECT_EQ(f.name, t.name);
    EXPECT_LT(std::abs(wrap_pm_pi(f.angle - t.angle)), angle_tol) << t.name;
    EXPECT_NEAR(f.strength / t.strength, 1.0, strength_tol) << t.name;
    EXPECT_NEAR(f.shape_factor / t.shape_factor, 1.0, shape_tol) << t.name;
  }
}

} // namespace

TEST(CmdFlux, HelpAndUsage)
{
  const CommandResult help = run_magbrush("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_TRUE(contains(help.output, "Usage: magbrush flux CASE"));
  const CommandResult unknown = run_magbrush("case.yaml --frobnicate");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_TRUE(contains(unknown.output, "unknown option '--frobnicate'")) << unknown.output;
  const CommandResult none = run_magbrush("");
  EXPECT_EQ(none.status, 2);
}

TEST(CmdFlux, FitOnTheExampleScanRecoversItsHeaderPoles)
{
  const fs::path dir = scratch("example");
  const fs::path case_file = write_case(dir);
  // Overrides are carried into the fitted file (the one on a list element by its name is
  // replaced by the fit, of course).
  const CommandResult r = run_magbrush(case_file.string() + " --measured " + example_scan_path() + " -o " +
                             (dir / "out").string() + " --fit --no-fem-check --no-plot" +
                             " --set sleeve.thickness=0.2mm --set roller.poles.N1.strength=160kA/m");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "exact multipole ring")) << r.output;
  EXPECT_TRUE(contains(r.output, "FEM check skipped")) << r.output;
  for (const char *f : {"flux_profile.csv", "flux_residuals.csv", "flux_fit_residuals.csv",
                        "flux_fit.txt", "example_roller_fitted.yaml"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  expect_flux_outputs_consistent(dir / "out");
  const Case fitted = load_case((dir / "out" / "example_roller_fitted.yaml").string());
  EXPECT_EQ(fitted.name, "example_roller_fitted");
  EXPECT_DOUBLE_EQ(fitted.sleeve->thickness, 0.2e-3);
  expect_poles_near(*fitted.roller, example_roller(), 0.1 * deg, 0.01, 0.01);
  // Before the fit the design poles are ~10 % off; the comparison shows it.
  EXPECT_TRUE(contains(r.output, "Scan against the fitted pole model")) << r.output;
}

namespace {

// Truth: the design layout with zero-mean deviations, other strengths, α = 12.
Roller synthetic_truth()
{
  Roller truth = example_roller();
  const double angles[] = {1.0, 71.0, 143.0, 216.0, 289.0}; // mean = 144 = the design's mean
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    truth.poles[i].angle = angles[i] * deg;
    truth.poles[i].shape_factor = 12.0;
  }
  return truth;
}

// A scan of `truth` read by an encoder `offset` behind (scan angle = roller angle − offset),
// written in radians and gauss with other column names, noise 0.4 mT.
fs::path write_synthetic_scan(const fs::path &dir, const Roller &truth, double offset)
{
  std::vector<double> scan_angle, roller_angle, Bn, Bt;
  for (int k = 0; k < 240; ++k)
  {
    scan_angle.push_back(k * 1.5 * deg);
    roller_angle.push_back(k * 1.5 * deg + offset);
  }
  MultipoleRing(truth).profile(10e-3, roller_angle, Bn, Bt);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.4e-3);
  const fs::path scan = dir / "scan.txt";
  std::ofstream out(scan);
  out << "# synthetic scan, gauss, radians\ntheta [rad]; B_theta (G); B_r (G)\n";
  out.precision(10);
  for (size_t k = 0; k < scan_angle.size(); ++k)
    out << scan_angle[k] << "; " << (Bt[k] + noise(rng)) * 1e4 << "; " << (Bn[k] + noise(rng)) * 1e4
        << "\n";
  return scan;
}

// The number after the first `label` at or after `from` in `text` (NaN when absent).
double number_after(const std::string &text, const std::string &label, size_t from = 0)
{
  const auto at = text.find(label, from);
  return at == std::string::npos ? NAN : std::atof(text.c_str() + at + label.size());
}

} // namespace

TEST(CmdFlux, FitRecoversASyntheticScanWithOffsetInOtherUnits)
{
  // The scan is read by an encoder 2.5° behind, written in radians and gauss, noise 0.4 mT.
  const Roller truth = synthetic_truth();
  const double offset = 2.5 * deg;
  const fs::path dir = scratch("synthetic");
  const fs::path case_file = write_case(dir);
  const fs::path scan = write_synthetic_scan(dir, truth, offset);
  const CommandResult r = run_magbrush(case_file.string() + " --measured " + scan.string() + " -o " +
                             (dir / "out").string() + " --fit --no-fem-check --no-plot");
  ASSERT_EQ(r.status, 0) << r.output;
  const Case fitted = load_case((dir / "out" / "example_roller_fitted.yaml").string());
  expect_poles_near(*fitted.roller, truth, 0.1 * deg, 0.01, 0.01);
  // The encoder offset is in the report: "encoder offset 2.5xxx ± ..."
  const auto at = r.output.find("encoder offset ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const double reported = std::atof(r.output.c_str() + at + 15);
  std::printf("synthetic scan: encoder offset %.4f deg (true 2.5)\n", reported);
  EXPECT_NEAR(reported, 2.5, 0.05);

  // The same with the offset given (--angle-offset) and every angle free (--no-offset).
  const CommandResult given = run_magbrush(case_file.string() + " --measured " + scan.string() +
                                           " --angle-offset 2.5deg --no-offset -o " +
                                           (dir / "given").string() + " --fit --no-fem-check --no-plot");
  ASSERT_EQ(given.status, 0) << given.output;
  const Case fitted_given = load_case((dir / "given" / "example_roller_fitted.yaml").string());
  expect_poles_near(*fitted_given.roller, truth, 0.1 * deg, 0.01, 0.01);
}

TEST(CmdFlux, FittedCaseCarriesTheEncoderOffsetIntoLaterComparisons)
{
  // The fitted case records the scan's angular origin (the fitted encoder offset): the
  // comparison right after the fit and a later `magbrush flux` of the fitted case (scan from
  // its measured_flux_file, no --measured) both line the scan up with the fitted poles, so
  // their RMS errors are the fit's residual, not the error of a scan 2.5° off.
  const fs::path dir = scratch("origin");
  const fs::path case_file = write_case(dir);
  const fs::path scan = write_synthetic_scan(dir, synthetic_truth(), 2.5 * deg);
  const CommandResult fit = run_magbrush(case_file.string() + " --measured " + scan.string() +
                                         " -o " + (dir / "out").string() +
                                         " --fit --no-fem-check --no-plot");
  ASSERT_EQ(fit.status, 0) << fit.output;
  const fs::path fitted_file = dir / "out" / "example_roller_fitted.yaml";
  const Case fitted = load_case(fitted_file.string());
  EXPECT_NEAR(fitted.measured_flux_angle_origin, 2.5 * deg, 0.05 * deg);

  const double residual_bn = number_after(fit.output, "(Bn ", fit.output.find("residual RMS "));
  const double after_fit_bn =
      number_after(fit.output, "  Bn ", fit.output.find("Scan against the fitted pole model"));
  const CommandResult later =
      run_magbrush(fitted_file.string() + " -o " + (dir / "later").string() + " --no-plot");
  ASSERT_EQ(later.status, 0) << later.output;
  EXPECT_TRUE(contains(later.output, "scan angular origin 2.")) << later.output;
  const double later_bn = number_after(later.output, "  Bn ", later.output.find("Scan against"));
  std::printf("Bn RMS: fit residual %.4f, after the fit %.4f, later run of the fitted case %.4f mT\n",
              residual_bn, after_fit_bn, later_bn);
  EXPECT_NEAR(after_fit_bn / residual_bn, 1.0, 0.03);
  EXPECT_NEAR(later_bn / residual_bn, 1.0, 0.03);
}

TEST(CmdFlux, UsesTheFiniteElementProfileWhenPresent)
{
  // A stand-in for magbrush-field's output: the exact profile in its file format.
  const fs::path dir = scratch("fem");
  const fs::path case_file = write_case(dir);
  const fs::path fields = dir / "fields";
  fs::create_directories(fields);
  Roller design = example_roller();
  design.poles = {{"S1", 0, -300e3, 10}, {"N1", 70 * deg, 150e3, 10}, {"S2", 145 * deg, -150e3, 10},
                  {"S3", 215 * deg, -150e3, 10}, {"N2", 290 * deg, 150e3, 10}};
  std::vector<double> a, Bn, Bt;
  for (int k = 0; k < 720; ++k)
    a.push_back(k * 0.5 * deg);
  MultipoleRing(design).profile(10e-3, a, Bn, Bt);
  {
    std::ofstream out(fields / "example_roller_profile_probe.csv");
    out << "# Computed sleeve flux profile of case 'example_roller' (magbrush-field, FE_Q(2)), "
           "radius 10 mm.\n# angle counter-clockwise from +x; Bn positive outward, Bt positive "
           "counter-clockwise.\nangle_deg,Bn_T,Bt_T\n";
    out.precision(12);
    for (size_t k = 0; k < a.size(); ++k)
      out << a[k] / deg << "," << Bn[k] << "," << Bt[k] << "\n";
  }
  const std::string common = case_file.string() + " --set field.output_dir=" + fields.string() +
                             " --measured " + example_scan_path() + " --no-plot -o " +
                             (dir / "out").string();
  const CommandResult fem = run_magbrush(common);
  ASSERT_EQ(fem.status, 0) << fem.output;
  EXPECT_TRUE(contains(fem.output, "finite-element field")) << fem.output;
  const CommandResult ring = run_magbrush(common + " --source ring");
  ASSERT_EQ(ring.status, 0) << ring.output;
  EXPECT_TRUE(contains(ring.output, "exact multipole ring")) << ring.output;
  // Same profile, so the same error table (to the interpolation error, < 0.01 mT).
  auto rms_bn = [](const std::string &out) {
    const auto at = out.find("  Bn ");
    return std::atof(out.c_str() + at + 5);
  };
  EXPECT_NEAR(rms_bn(fem.output), rms_bn(ring.output), 0.01);
  // A profile at another radius is not used.
  const CommandResult other = run_magbrush(common + " --set field.probe_radius=11mm");
  ASSERT_EQ(other.status, 0) << other.output;
  EXPECT_TRUE(contains(other.output, "not the probe radius")) << other.output;
  const CommandResult must = run_magbrush(common + " --set field.probe_radius=11mm --source fem");
  EXPECT_EQ(must.status, 1) << must.output;

  // The stored magnetic field records the case it was computed for: with a grid file of the
  // case as it is, the profile is used; after a pole changes, it is stale and not used.
  const Case current = load_case(case_file.string(), {"field.output_dir=" + fields.string()});
  PolarGrid grid;
  grid.r_min = 10e-3;
  grid.r_max = 12e-3;
  grid.n_r = 4;
  grid.n_theta = 8;
  grid.A_z.assign(32, 0.0);
  write_magnetic_grid((fields / "example_roller_magnetic.h5").string(), grid,
                      case_provenance(current, FieldKind::magnetic));
  const CommandResult fresh = run_magbrush(common);
  ASSERT_EQ(fresh.status, 0) << fresh.output;
  EXPECT_TRUE(contains(fresh.output, "finite-element field")) << fresh.output;
  const CommandResult stale = run_magbrush(common + " --set roller.poles.N1.strength=100kA/m");
  ASSERT_EQ(stale.status, 0) << stale.output;
  EXPECT_TRUE(contains(stale.output, "is stale") && contains(stale.output, "roller.poles.N1.strength"))
      << stale.output;
  EXPECT_TRUE(contains(stale.output, "exact multipole ring")) << stale.output;
}

TEST(CmdFlux, BadInputGivesClearErrors)
{
  const fs::path dir = scratch("bad");
  const fs::path case_file = write_case(dir);
  const std::string out = " -o " + (dir / "out").string() + " --no-plot";

  const CommandResult missing = run_magbrush(case_file.string() + " --measured /nonexistent/scan.csv" + out);
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(contains(missing.output, "/nonexistent/scan.csv: cannot open")) << missing.output;

  const fs::path bad = dir / "bad.csv";
  std::ofstream(bad) << "angle_deg,Bn_mT,Bt_mT\n0,1,2\n1,1,2\n2,x,2\n";
  const CommandResult cell = run_magbrush(case_file.string() + " --measured " + bad.string() + out);
  EXPECT_EQ(cell.status, 1);
  EXPECT_TRUE(contains(cell.output, "bad.csv:4:") && contains(cell.output, "'x'")) << cell.output;

  const CommandResult inside = run_magbrush(case_file.string() + " --set field.probe_radius=8mm --measured " +
                                  example_scan_path() + out);
  EXPECT_EQ(inside.status, 1);
  EXPECT_TRUE(contains(inside.output, "inside the magnet")) << inside.output;

  const CommandResult no_scan = run_magbrush(case_file.string() + " --fit" + out);
  EXPECT_EQ(no_scan.status, 1);
  EXPECT_TRUE(contains(no_scan.output, "--fit needs a scan")) << no_scan.output;

  const CommandResult no_case = run_magbrush("/nonexistent/case.yaml" + out);
  EXPECT_EQ(no_case.status, 1);

  // Without a scan: the computed profile and its peaks only.
  const CommandResult profile_only = run_magbrush(case_file.string() + out);
  EXPECT_EQ(profile_only.status, 0) << profile_only.output;
  EXPECT_TRUE(contains(profile_only.output, "computed peaks only")) << profile_only.output;
}

TEST(CmdFlux, MissingPythonOnlyWarns)
{
  const fs::path dir = scratch("nopython");
  const fs::path case_file = write_case(dir);
  const CommandResult r = run_magbrush(case_file.string() + " --measured " + example_scan_path() + " -o " +
                                 (dir / "out").string(),
                             "MAGBRUSH_PYTHON=/nonexistent/python3");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "warning: python3 not found")) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "flux_residuals.csv"));
  EXPECT_FALSE(fs::exists(dir / "out" / "flux_overlay.png"));
}

TEST(CmdFlux, WritesTheOverlayPlotWhenMatplotlibIsAvailable)
{
  if (std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "no /usr/bin/python3 with matplotlib here";
  const fs::path dir = scratch("plot");
  const fs::path case_file = write_case(dir);
  const CommandResult r = run_magbrush(case_file.string() + " --measured " + example_scan_path() +
                                           " -o " + (dir / "out").string() + " --fit --no-fem-check",
                                       "MAGBRUSH_PYTHON=/usr/bin/python3");
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path png = dir / "out" / "flux_overlay.png";
  ASSERT_TRUE(fs::exists(png)) << r.output;
  EXPECT_GT(fs::file_size(png), 20000u);
  std::ifstream in(png, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

// `--compare OTHER`: two cases' profiles and each pole's peak shift, against what symmetry and
// linearity say independently of any peak finder: the whole roller turned by 5° moves every
// peak by +5° and leaves every peak value as it was (the ring's field turns with it); every
// pole 10 % stronger leaves the angles and raises every peak by 10 % (the field is linear in
// the magnetisation, the magnet being linear, μr = 1).
TEST(CmdFlux, CompareTwoCasesGivesEachPolesPeakShift)
{
  using magbrush::testing::read_csv_columns;
  const fs::path dir = scratch("compare");
  const fs::path case_file = write_case(dir);
  const Case c = load_case(case_file.string());
  constexpr double to_deg = 180.0 / M_PI;
  std::string turned, stronger;
  for (const Pole &p : c.roller->poles)
  {
    turned += " --compare-set roller.poles." + p.name + ".angle=" + std::to_string(p.angle * to_deg + 5.0) + "deg";
    stronger += " --compare-set roller.poles." + p.name + ".strength=" + std::to_string(1.1 * p.strength * 1e-3) + "kA/m";
  }
  const std::string both = case_file.string() + " --compare " + case_file.string() + " --source ring --no-plot";

  const CommandResult r = run_magbrush(both + turned + " -o " + (dir / "turned").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "both from the exact multipole ring")) << r.output;
  auto peaks = read_csv_columns(dir / "turned" / "flux_compare_peaks.csv");
  ASSERT_EQ(peaks["pole"].size(), c.roller->poles.size());
  for (size_t i = 0; i < peaks["pole"].size(); ++i)
  {
    SCOPED_TRACE(peaks["pole"][i]);
    EXPECT_NEAR(std::stod(peaks["shift_deg"][i]), 5.0, 0.01);
    EXPECT_NEAR(std::stod(peaks["dBn_mT"][i]), 0.0, 0.01);
  }
  const auto profiles = read_csv_columns(dir / "turned" / "flux_compare.csv");
  EXPECT_EQ(profiles.at("angle_deg").size(), 1440u);

  const CommandResult s = run_magbrush(both + stronger + " -o " + (dir / "stronger").string());
  ASSERT_EQ(s.status, 0) << s.output;
  peaks = read_csv_columns(dir / "stronger" / "flux_compare_peaks.csv");
  ASSERT_EQ(peaks["pole"].size(), c.roller->poles.size());
  for (size_t i = 0; i < peaks["pole"].size(); ++i)
  {
    SCOPED_TRACE(peaks["pole"][i]);
    EXPECT_NEAR(std::stod(peaks["shift_deg"][i]), 0.0, 0.01);
    EXPECT_NEAR(std::stod(peaks["peak_change_percent"][i]), 10.0, 0.01);
  }

  // A scan's options have no meaning here; --compare-set needs a case to change.
  const CommandResult with_scan = run_magbrush(both + " --measured " + example_scan_path());
  EXPECT_EQ(with_scan.status, 2);
  EXPECT_TRUE(contains(with_scan.output, "--measured is for a gaussmeter scan")) << with_scan.output;
  const CommandResult alone = run_magbrush(case_file.string() + " --compare-set roller.poles.N1.angle=5deg");
  EXPECT_EQ(alone.status, 2);
  EXPECT_TRUE(contains(alone.output, "add --compare OTHER_CASE")) << alone.output;
}
