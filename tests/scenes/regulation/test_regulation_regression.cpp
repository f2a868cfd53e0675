// The DMA study end to end on the regulation cell (cases/kweon_regulation.yaml: the sector of
// Kweon's roller around the doctor blade, oversupplied by an inflow before it, the excess
// spilling off the pile in front of it, the regulated layer measured past it), through
// `magbrush sweep` exactly as a user runs the study (check, field, DEM, table and plots), at two
// blade gaps, shortened to 11 ms, the DMA window moved 3° nearer the blade (275–283°: the layer
// reaches it after about 6 ms; averaged from 8.5 ms, while the layer still builds up: averaged
// from 7 to 9 ms the two gaps differed by only 1.6 combined standard errors).
//
// What must hold at any moment of regulation, steady or not — and what the test asserts:
//  * the blade regulates: a wider gap lets more developer through, by two standard errors;
//  * below the bound ρ_bulk × gap (the sweep's column next to the DMA): a layer cannot leave
//    the gap denser than a random close packing moving with the sleeve;
//  * the blade holds developer back: there is a pile in front of it and a load on it;
//  * the rough sleeve carries the layer through the gap: the developer under the blade tip
//    moves at 0.8-1.1 of the sleeve's speed (0.96 and 0.99 in one run; a smooth sleeve under a
//    grown pile slid to 0.5 in the full roller, docs/regulation.md; nothing drives the gap's
//    layer faster than the sleeve);
//  * mass is conserved to the particle: at every row of each point's flow report, the beads
//    present are those created minus those removed, and their masses agree likewise;
//  * the table has what a user plots: standard errors, the bound, the run time, the plot.
//
// Cost: about 2 × 5 min on 2 idle cores in Release (2 × 14 min on a loaded machine).
#include "tests/scenes/sweep_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

TEST(RegulationRegression, DmaRisesWithTheBladeGapBelowTheBulkBoundAndMassIsConserved)
{
  const fs::path dir = magbrush::testing::run_sweep_study(
      "regulation_regression", "'" MAGBRUSH_SOURCE_DIR "/cases/kweon_regulation.yaml' --vary "
                               "blades.doctor.gap=0.3mm,0.6mm --name gap --set dem.duration=11ms "
                               "--set dma.after_blade=9deg --set dma.average_from=8.5ms");
  ASSERT_FALSE(dir.empty());
  const fs::path sweep = dir / "results" / "sweep_gap";
  const auto table = magbrush::testing::read_csv_columns(sweep / "sweep_summary.csv");
  for (const char *column : {"dma_kg_per_m2", "dma_kg_per_m2_stderr", "dma_kg_per_m2_bound", "dma_flux_kg_per_m2",
                             "blade_force_N_per_m", "developer_held_in_front_of_blade_kg_per_m",
                             "blade_gap_speed_ratio", "run_time_s"})
  {
    ASSERT_TRUE(table.count(column)) << "sweep_summary.csv has no column " << column;
    ASSERT_EQ(table.at(column).size(), 2u) << column;
  }
  auto value = [&](const char *column, int point) { return std::atof(table.at(column)[point].c_str()); };
  const double narrow = value("dma_kg_per_m2", 0), wide = value("dma_kg_per_m2", 1);
  std::printf("DMA %.4g ± %.2g kg/m^2 at 0.3 mm, %.4g ± %.2g kg/m^2 at 0.6 mm; bounds %.4g, %.4g; flux form %.4g, "
              "%.4g; blade %.3g, %.3g N/m; held %.3g, %.3g kg/m; gap speed / sleeve %.3g, %.3g\n",
              narrow, value("dma_kg_per_m2_stderr", 0), wide, value("dma_kg_per_m2_stderr", 1),
              value("dma_kg_per_m2_bound", 0), value("dma_kg_per_m2_bound", 1), value("dma_flux_kg_per_m2", 0),
              value("dma_flux_kg_per_m2", 1), value("blade_force_N_per_m", 0), value("blade_force_N_per_m", 1),
              value("developer_held_in_front_of_blade_kg_per_m", 0),
              value("developer_held_in_front_of_blade_kg_per_m", 1), value("blade_gap_speed_ratio", 0),
              value("blade_gap_speed_ratio", 1));

  EXPECT_GT(narrow, 0.0) << "no developer passed the 0.3 mm gap";
  const double se = std::hypot(value("dma_kg_per_m2_stderr", 0), value("dma_kg_per_m2_stderr", 1));
  EXPECT_GT(se, 0.0);
  EXPECT_GT(wide - narrow, 2.0 * se) << "the DMA must rise with the blade gap, by two standard errors";
  for (int p = 0; p < 2; ++p)
  {
    EXPECT_LT(value("dma_kg_per_m2", p), value("dma_kg_per_m2_bound", p)) << "point " << p;
    EXPECT_GT(value("blade_force_N_per_m", p), 0.0) << "point " << p;
    EXPECT_GT(value("developer_held_in_front_of_blade_kg_per_m", p), 0.0) << "point " << p;
    EXPECT_GT(value("blade_gap_speed_ratio", p), 0.8) << "point " << p << ": the sleeve slides under the gap's layer";
    EXPECT_LT(value("blade_gap_speed_ratio", p), 1.1) << "point " << p;
    EXPECT_GT(value("run_time_s", p), 0.0);
  }
  // The bound is ρ_bulk × gap: the gaps' ratio.
  EXPECT_NEAR(value("dma_kg_per_m2_bound", 1) / value("dma_kg_per_m2_bound", 0), 2.0, 1e-5); // CSV: 6 digits
  EXPECT_TRUE(fs::exists(sweep / "sweep_dma_kg_per_m2.png"));

  // Mass conserved to the particle in each point (its flow report: in, out, present).
  EXPECT_EQ(magbrush::testing::expect_flow_budgets_close(sweep), 2);
}
