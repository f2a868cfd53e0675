// `magbrush flux CASE --compare OTHER`: two sleeve-flux profiles overlaid, each pole's peak
// shift. The steps, as compare_case_fluxes() reads:
//   1. load both cases (--set on both, --compare-set on the other only) and their probe radii;
//   2. choose one source for both profiles: the FEM's when both have a current one, else the
//      exact ring for both (a mixed pair would show the solvers' difference as a layout's);
//   3. both profiles on a 0.25° grid, each pole's peak in each (poles matched by name; the
//      parabola through the top of the peak, calibration/flux_compare.h), the shifts;
//   4. print the table, write the two CSVs, plot.
#include "app/flux_case_comparison.h"
#include "app/flux_tools.h"

#include "calibration/flux_compare.h"
#include "common/atomic_file.h"
#include "case/case_parser.h"
#include "fields/multipole_ring.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;
constexpr double to_deg = 180.0 / M_PI;

// One side of the comparison: the case, where it is probed, and its profile.
struct Side
{
  Case c;
  std::string label; // "kawamoto_nip_fed" or "kawamoto_nip_fed (roller.poles.S1.angle=5 deg)"
  double probe_radius = 0.0;
  std::string fem_path, why_not_fem;
  ComputedProfile profile;
  std::vector<PeakMatch> peaks; // per pole of c
};

Side load_side(const std::string &path, const std::vector<std::string> &overrides)
{
  Side s;
  s.c = load_case(path, overrides);
  s.label = s.c.name;
  if (!s.c.output.overrides.empty())
  {
    std::string list;
    for (const auto &o : s.c.output.overrides)
      list += (list.empty() ? "" : ", ") + o;
    s.label += " (" + list + ")";
  }
  s.probe_radius = probe_radius_of(s.c);
  return s;
}

// "A - B" of two angles in degrees, in (-180, 180].
double angle_difference_deg(double a_rad, double b_rad)
{
  return std::remainder((a_rad - b_rad) * to_deg, 360.0);
}

// A peak's angle in degrees next to its pole's (in [0, 360)): a peak of the pole at 0 deg
// reads 0.01 or -0.01, one of the pole at 216 deg 216.18, not -143.82.
double near_pole_deg(double peak_rad, const Pole &pole)
{
  const double pole_deg = std::fmod(std::fmod(pole.angle * to_deg, 360.0) + 360.0, 360.0);
  return pole_deg + angle_difference_deg(peak_rad, pole_deg / to_deg);
}

const Pole *pole_named(const Case &c, const std::string &name)
{
  for (const auto &p : c.roller->poles)
    if (p.name == name)
      return &p;
  return nullptr;
}

// The other side's peak of the pole with this name (nullopt: no such pole, or no peak).
std::optional<PeakMatch> peak_named(const Side &s, const std::string &name)
{
  for (size_t i = 0; i < s.c.roller->poles.size(); ++i)
    if (s.c.roller->poles[i].name == name && s.peaks[i].found)
      return s.peaks[i];
  return std::nullopt;
}

// Step 2: the FEM for both when both have one for the case as it is now, else the ring for both.
bool use_fem_for_both(Side &a, Side &b, const std::string &source)
{
  if (source == "ring")
  {
    a.why_not_fem = b.why_not_fem = "--source ring";
    return false;
  }
  a.fem_path = fem_profile_path(a.c, a.probe_radius, a.why_not_fem);
  b.fem_path = fem_profile_path(b.c, b.probe_radius, b.why_not_fem);
  const bool both = !a.fem_path.empty() && !b.fem_path.empty();
  if (source == "fem" && !both)
    throw std::invalid_argument("--source fem: " + std::string(a.fem_path.empty() ? "A: " + a.why_not_fem
                                                                                  : "B: " + b.why_not_fem));
  if (!both)
    a.fem_path.clear(), b.fem_path.clear();
  return both;
}

void write_profiles_csv(const std::string &path, const Side &a, const Side &b, const std::vector<double> &grid,
                        const std::string &source)
{
  std::ostringstream out;
  out << "# Sleeve flux of two cases, from the " << source << ".\n"
      << "# A: " << a.label << " at radius " << fixed(a.probe_radius * 1e3, 3) << " mm\n"
      << "# B: " << b.label << " at radius " << fixed(b.probe_radius * 1e3, 3) << " mm\n"
      << "# angle counter-clockwise from +x; Bn positive outward, Bt positive counter-clockwise.\n"
      << "angle_deg,Bn_A_mT,Bt_A_mT,Bn_B_mT,Bt_B_mT,dBn_mT,dBt_mT\n";
  char buf[256];
  for (size_t k = 0; k < grid.size(); ++k)
  {
    const double an = a.profile.Bn[k], at = a.profile.Bt[k], bn = b.profile.Bn[k], bt = b.profile.Bt[k];
    std::snprintf(buf, sizeof buf, "%.4f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", grid[k] * to_deg, an * 1e3, at * 1e3,
                  bn * 1e3, bt * 1e3, (bn - an) * 1e3, (bt - at) * 1e3);
    out << buf;
  }
  write_text_atomically(path, out.str());
}

} // namespace

int compare_case_fluxes(const FluxCaseComparisonOptions &o)
{
  // 1. The two cases.
  Side a = load_side(o.case_path, o.overrides);
  std::vector<std::string> other_overrides = o.overrides;
  other_overrides.insert(other_overrides.end(), o.other_overrides.begin(), o.other_overrides.end());
  Side b = load_side(o.other_path, other_overrides);
  std::cout << "magbrush flux --compare:\n"
            << "  A  " << a.label << ", " << a.c.roller->poles.size() << " poles, probe radius "
            << fixed(a.probe_radius * 1e3, 3) << " mm\n"
            << "  B  " << b.label << ", " << b.c.roller->poles.size() << " poles, probe radius "
            << fixed(b.probe_radius * 1e3, 3) << " mm\n";
  if (std::abs(a.probe_radius - b.probe_radius) > 1e-9)
    std::cout << "  note: the probe radii differ; each profile is taken at its own case's radius, as a "
                 "gaussmeter would scan each roller\n";

  // 2. One source for both.
  const bool fem = use_fem_for_both(a, b, o.source);
  MultipoleRing::Options ring_options;
  ring_options.harmonics = o.harmonics;
  const MultipoleRing ring_a(*a.c.roller, ring_options), ring_b(*b.c.roller, ring_options);
  const std::string source = fem ? "finite-element profiles (magbrush field)" : "exact multipole ring";
  std::cout << "  both from the " << source;
  if (!fem && o.source != "ring")
    std::cout << " (" << (a.why_not_fem.empty() ? "B: " + b.why_not_fem : "A: " + a.why_not_fem)
              << "; one source for both, so that the difference is the layouts')";
  std::cout << "\n";

  // 3. The profiles and the peaks.
  std::vector<double> grid;
  for (int k = 0; k < 1440; ++k)
    grid.push_back(k * 0.25 / to_deg);
  a.profile = computed_at(grid, ring_a, a.probe_radius, a.fem_path);
  b.profile = computed_at(grid, ring_b, b.probe_radius, b.fem_path);
  a.peaks = find_pole_peaks(a.c.roller->poles, grid, a.profile.Bn);
  b.peaks = find_pole_peaks(b.c.roller->poles, grid, b.profile.Bn);

  // 4. The table, the files, the plot.
  const std::string dir =
      o.output_dir.empty()
          ? (fs::path(a.c.output.directory) / "flux" / ("compare_" + fs::path(b.c.output.directory).filename().string()))
                .string()
          : o.output_dir;
  fs::create_directories(dir);
  std::ostringstream peaks_csv, table;
  peaks_csv << "# Each pole's sleeve-flux peak (Bn) in A and B, from the " << source << "; shift and dBn = B - A;\n"
            << "# peak_change_percent = (|Bn_B| - |Bn_A|) / |Bn_A|: + for a stronger peak of either sign.\n"
            << "# A: " << a.label << "\n# B: " << b.label << "\n"
            << "pole,angle_A_deg,Bn_A_mT,angle_B_deg,Bn_B_mT,shift_deg,dBn_mT,peak_change_percent\n";
  table << "\n  pole   A: angle [deg]  Bn [mT]   B: angle [deg]  Bn [mT]   shift [deg]   ΔBn [mT]   |Bn| change\n";
  char buf[256];
  std::vector<std::string> seen;
  for (size_t i = 0; i < a.c.roller->poles.size(); ++i)
  {
    const std::string &name = a.c.roller->poles[i].name;
    seen.push_back(name);
    const PeakMatch &pa = a.peaks[i];
    const std::optional<PeakMatch> pb = peak_named(b, name);
    if (!pa.found || !pb)
    {
      const std::string why = !pole_named(b.c, name) ? "not a pole of B" : "no resolved peak";
      std::snprintf(buf, sizeof buf, "  %-5s  %s\n", name.c_str(), why.c_str());
      table << buf;
      peaks_csv << name << ",,,,,,,\n";
      continue;
    }
    const double shift = angle_difference_deg(pb->angle, pa.angle), dbn = (pb->value - pa.value) * 1e3;
    // The peak's size, whatever the pole's sign: a stronger south pole reads +, like a north one.
    const double percent = 100.0 * (std::abs(pb->value) - std::abs(pa.value)) / std::abs(pa.value);
    std::snprintf(buf, sizeof buf, "  %-5s  %13.2f  %8.2f   %13.2f  %8.2f   %+10.2f   %+8.2f   %+6.1f %%\n",
                  name.c_str(), near_pole_deg(pa.angle, a.c.roller->poles[i]), pa.value * 1e3,
                  near_pole_deg(pb->angle, a.c.roller->poles[i]), pb->value * 1e3, shift, dbn, percent);
    table << buf;
    std::snprintf(buf, sizeof buf, "%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f\n", name.c_str(),
                  near_pole_deg(pa.angle, a.c.roller->poles[i]), pa.value * 1e3,
                  near_pole_deg(pb->angle, a.c.roller->poles[i]), pb->value * 1e3, shift, dbn, percent);
    peaks_csv << buf;
  }
  for (const auto &p : b.c.roller->poles)
    if (std::find(seen.begin(), seen.end(), p.name) == seen.end())
      table << "  " << p.name << "  a pole of B only (at " << fixed(p.angle * to_deg, 2) << " deg)\n";
  // The largest change anywhere on the sleeve, which a peak table can miss (a flank moved).
  size_t worst = 0;
  for (size_t k = 0; k < grid.size(); ++k)
    if (std::abs(b.profile.Bn[k] - a.profile.Bn[k]) > std::abs(b.profile.Bn[worst] - a.profile.Bn[worst]))
      worst = k;
  table << "  largest |ΔBn| on the sleeve: " << fixed(std::abs(b.profile.Bn[worst] - a.profile.Bn[worst]) * 1e3, 2)
        << " mT at " << fixed(grid[worst] * to_deg, 2) << " deg\n"
        << "  (peaks: the parabola through the top 5 % of each pole's Bn; shift = B − A)\n";
  std::cout << table.str();

  const std::string profiles = dir + "/flux_compare.csv", peaks = dir + "/flux_compare_peaks.csv";
  write_profiles_csv(profiles, a, b, grid, source);
  write_text_atomically(peaks, peaks_csv.str());
  std::cout << "\n  profiles    " << profiles << "\n  peaks       " << peaks << "\n";
  if (!o.no_plot)
    run_plot_script("plot_flux_compare.py",
                    {"--profiles", profiles, "--peaks", peaks, "--label-a", "A: " + a.label, "--label-b",
                     "B: " + b.label, "-o", dir + "/flux_compare.png"},
                    dir + "/flux_compare.png");
  return 0;
}

} // namespace magbrush
