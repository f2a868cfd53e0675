// The TMA study end to end on a development cell (tests/scenes/development/development_cell.yaml:
// cases/kweon_development.yaml reduced to 200 carriers and ~2,600 toner seeded in the gap, 60 µs),
// through `magbrush sweep` exactly as a user runs the study (check, field, DEM, the sweep's table
// and plots), at two biases.
//
// What must hold at any moment of development, steady or not — the test asserts that and no
// more (the transient is not the paper's steady TMA):
//  * the image develops: toner on the exposed strips, more at the higher contrast (the force qE
//    that pulls toner off the carriers grows with the bias; the cell, the seed and the random
//    streams are the same at both points);
//  * below the neutralisation bound ε0 εr ΔV / (L |q/m|) at each bias, the column the sweep
//    writes next to the TMA (the developed charge cannot overshoot the latent image's);
//  * the background (dark strips at −800 V, a cleaning field) gets far less than the image;
//  * the table has what a user plots: the standard error, the bound, the run time, and the plot.
//
// Cost: about 2 × 1 min on 2 cores in Release.
#include "tests/csv_columns.h"
#include "tests/scenes/sweep_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

TEST(DevelopmentRegression, TmaRisesWithBiasBelowTheNeutralisationBoundWithLittleFog)
{
  const fs::path dir = magbrush::testing::run_sweep_study(
      "development_regression", "'" MAGBRUSH_SOURCE_DIR "/tests/scenes/development/development_cell.yaml' "
                                "--vary electric.bias=-200V,-800V --name bias");
  ASSERT_FALSE(dir.empty());
  const fs::path sweep = dir / "results" / "sweep_bias";
  const auto table = magbrush::testing::read_csv_columns(sweep / "sweep_summary.csv");
  for (const char *column : {"tma_kg_per_m2", "tma_kg_per_m2_stderr", "tma_kg_per_m2_bound", "fog_kg_per_m2",
                             "run_time_s"})
  {
    ASSERT_TRUE(table.count(column)) << "sweep_summary.csv has no column " << column;
    ASSERT_EQ(table.at(column).size(), 2u) << column;
  }
  auto value = [&](const char *column, int point) { return std::atof(table.at(column)[point].c_str()); };
  const double tma_low = value("tma_kg_per_m2", 0), tma_high = value("tma_kg_per_m2", 1);
  std::printf("TMA %.4g ± %.2g kg/m^2 at -200 V, %.4g ± %.2g kg/m^2 at -800 V; bounds %.4g, %.4g; fog %.3g, %.3g\n",
              tma_low, value("tma_kg_per_m2_stderr", 0), tma_high, value("tma_kg_per_m2_stderr", 1),
              value("tma_kg_per_m2_bound", 0), value("tma_kg_per_m2_bound", 1), value("fog_kg_per_m2", 0),
              value("fog_kg_per_m2", 1));

  EXPECT_GT(tma_low, 0.0) << "no toner developed onto the image at -200 V";
  const double se = std::hypot(value("tma_kg_per_m2_stderr", 0), value("tma_kg_per_m2_stderr", 1));
  EXPECT_GT(se, 0.0);
  EXPECT_GT(tma_high - tma_low, 2.0 * se) << "the image TMA must rise with the bias, by two standard errors";
  for (int p = 0; p < 2; ++p)
  {
    EXPECT_LT(value("tma_kg_per_m2", p), value("tma_kg_per_m2_bound", p)) << "point " << p;
    EXPECT_LT(value("fog_kg_per_m2", p), 0.2 * value("tma_kg_per_m2", p)) << "point " << p;
    EXPECT_GT(value("run_time_s", p), 0.0);
  }
  // The bound is the photoconductor's: ε0 εr ΔV / (L |q/m|), ΔV the bias against the 0 V image.
  EXPECT_NEAR(value("tma_kg_per_m2_bound", 1) / value("tma_kg_per_m2_bound", 0), 4.0, 1e-5); // CSV: 6 digits
  EXPECT_TRUE(fs::exists(sweep / "sweep_tma_kg_per_m2.png"));
}
