// The pole fit on a scan made by the finite-element field solver: the true roller of
// unseen_roller.h (per-pole shape factors) solved by bin/magbrush-field, its probe profile
// (1° steps, 13 mm) read as a gaussmeter would with an encoder 3.7° behind, plus 0.5 mT
// noise. The fit's forward model (the exact ring) never made this scan: what it sees is the
// FE solution, with its discretisation error (about 1e-3 of the peak at the default mesh,
// magbrush-field's own report) on top of the noise.
//
// Checked: `automatic` picks per-pole, recovers the poles and the offset, and the residual
// stays at the noise (the FE error adds little to it).
#include "calibration/flux_scan.h"
#include "calibration/pole_fit.h"
#include "tests/calibration/unseen_roller.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

using namespace magbrush;
using namespace magbrush::unseen;
namespace fs = std::filesystem;

namespace {

// The true roller as a case file for magbrush-field (probe radius = sleeve radius = 13 mm).
fs::path write_true_case(const fs::path &dir)
{
  const fs::path path = dir / "fe_roller.yaml";
  std::ofstream out(path);
  out.precision(12);
  out << "name: fe_roller\nscene: roller\nroller:\n  shaft_radius: 4 mm\n  shaft_mu_r: 1\n"
         "  magnet_radius: 12 mm\n  magnet_mu_r: 1\n  poles:\n";
  for (const Pole &p : true_roller(per_pole_alpha).poles)
    out << "    - {name: " << p.name << ", angle: " << p.angle / deg << " deg, strength: "
        << p.strength << " A/m, shape_factor: " << p.shape_factor << " rad^-2}\n";
  out << "sleeve:\n  radius: " << probe_radius * 1e3 << " mm\n  thickness: 0.3 mm\n"
      << "field:\n  output_dir: " << (dir / "fields").string() << "\n";
  return path;
}

// The FE probe profile as a scan: scan angle = roller angle − encoder offset, noise added.
FluxScan scan_from_fe_profile(const fs::path &profile)
{
  ScanReadOptions read;
  read.min_points = 16;
  read.angle_offset = -encoder_offset;
  FluxScan scan = read_flux_scan(profile.string(), read);
  std::mt19937 rng(13);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  for (size_t k = 0; k < scan.size(); ++k)
  {
    scan.Bn[k] += noise(rng);
    scan.Bt[k] += noise(rng);
  }
  return scan;
}

} // namespace

TEST(FiniteElementScan, PerPoleShapesAreChosenAndRecovered)
{
  const fs::path dir = magbrush::testing::test_temp_dir("fe_scan");
  const fs::path case_file = write_true_case(dir);
  const std::string command = std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush-field " +
                              case_file.string() + " --only magnetic --no-vtu > " +
                              (dir / "field.log").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << "see " << (dir / "field.log").string();

  const FluxScan scan = scan_from_fe_profile(dir / "fields" / "fe_roller_profile_probe.csv");
  const Roller truth = true_roller(per_pole_alpha);
  const PoleFitResult fit = fit_poles(design_roller(), scan, probe_radius); // automatic
  ASSERT_TRUE(fit.converged) << fit.status;
  const Worst w = worst_deviation(fit, truth);
  std::printf("FE scan: %s; %s\n", shape_name(fit.shape).c_str(), fit.shape_selection.reason.c_str());
  std::printf("  residual %.4f mT, noise estimate %.4f mT (true %.2f); worst pole: angle %.4f deg, "
              "strength %.3f %%, shape %.2f %%; offset %.4f deg (true %.2f)\n",
              fit.rms * 1e3, fit.noise_rms * 1e3, noise_sigma * 1e3, w.angle / deg,
              100 * w.strength, 100 * w.shape, fit.offset / deg, encoder_offset / deg);
  EXPECT_EQ(fit.shape, PoleFitOptions::Shape::per_pole);
  EXPECT_TRUE(residual_warning(fit).empty()) << residual_warning(fit);
  EXPECT_NEAR(fit.noise_rms / noise_sigma, 1.0, 0.2);
  EXPECT_LT(w.angle, 0.1 * deg);
  EXPECT_LT(w.strength, 0.01);
  EXPECT_LT(w.shape, 0.03);
  EXPECT_NEAR(fit.rms / noise_sigma, 1.0, 0.05);
  EXPECT_NEAR(fit.offset, encoder_offset, 0.05 * deg);
  const FluxComparison after = compare_with_fitted_model(scan, fit, probe_radius);
  EXPECT_NEAR(combined_rms(after) / fit.rms, 1.0, 0.02);
}
