// End-to-end: every measurement the engine makes, continued across a restart. Each scene that
// calls for a set of measurements runs once to its end (`magbrush run`, or `magbrush-dem` for a
// scene without fields), writing a checkpoint halfway; `magbrush-dem --restart` from that
// checkpoint then runs the second half into another folder. Its measurement files must be the
// uninterrupted run's, byte for byte: the samples before the restart come from the checkpoint,
// those after from the continued state (which the engine restores bit for bit).
//
//   nip scene with inflow      chain inclination, flow report, nip profile, nip time series
//   development cell           toner development (and the nip measurements with toner)
//   regulation sector          developer mass per area, flow report
//   release sector             developer release
//   compression box            plate compression (windows, contact maps)
//   development cell, 1 um image period: the developed line over whole image periods
#include <gtest/gtest.h>

#include "tests/cli_run.h"
#include "tests/test_temp_dir.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using magbrush::testing::CliResult;

CliResult run(const std::string &program, const std::string &args)
{
  return magbrush::testing::run_program(program, args);
}

std::string contents(const fs::path &file)
{
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Scene
{
  const char *name;
  const char *case_file; // relative to the source tree
  bool fields;           // run by `magbrush run` (fields, mesh, DEM) or by `magbrush-dem` alone
  const char *settings;  // --set ... of both halves: a short run with a checkpoint halfway
  std::vector<const char *> files; // the measurement files compared
};

// The test's name in listings (not the struct's bytes).
void PrintTo(const Scene &scene, std::ostream *os) { *os << scene.name; }

class MeasurementRestart : public ::testing::TestWithParam<Scene>
{
};

} // namespace

TEST_P(MeasurementRestart, RestartedRunWritesTheUninterruptedRunsFilesByteForByte)
{
  const Scene &scene = GetParam();
  const fs::path dir = magbrush::testing::test_temp_dir(std::string("measurement_restart_") + scene.name);
  const std::string case_file = std::string(MAGBRUSH_SOURCE_DIR) + "/" + scene.case_file;
  const std::string common = std::string(" ") + scene.settings + " --threads 1";
  const fs::path whole = scene.fields ? dir / "whole" / "dem" : dir / "whole";
  const CliResult a =
      scene.fields ? run("magbrush", "run '" + case_file + "' --set output.directory=" + (dir / "whole").string() + common)
                   : run("magbrush-dem", "'" + case_file + "'" + common + " --output " + whole.string());
  ASSERT_EQ(a.code, 0) << a.output;
  // The checkpoint halfway is the one kept before the final one.
  const fs::path halfway = dir / "halfway.bin";
  fs::copy_file(whole / "checkpoint.previous.bin", halfway);
  const fs::path continued = dir / "continued";
  // (magbrush-dem finds the fields where the whole run put them, <output.directory>/fields:
  // each scene's own, so the development cell's two scenes, whose fields differ, never share one.)
  const CliResult b = run("magbrush-dem", "'" + case_file + "'" + common + " --set output.directory=" +
                                              (dir / "whole").string() + " --restart " + halfway.string() +
                                              " --output " + continued.string());
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_NE(b.output.find("the measurements continue from the checkpoint"), std::string::npos) << b.output;
  // The restarted run keeps the checkpoint's step and says so.
  EXPECT_NE(b.output.find("(the checkpoint's; stable limit"), std::string::npos) << b.output;
  for (const char *file : scene.files)
  {
    ASSERT_TRUE(fs::exists(whole / file)) << file << " was not written by the whole run";
    const std::string expected = contents(whole / file), got = contents(continued / file);
    EXPECT_GT(expected.size(), 0u) << file;
    EXPECT_TRUE(expected == got) << file << " differs after the restart:\n--- whole run\n"
                                 << expected.substr(0, 2000) << "\n--- restarted\n" << got.substr(0, 2000);
  }
  // The developed line's periods closed on both sides of the restart (header lines: 2).
  if (std::string(scene.name) == "development_periods" || std::string(scene.name) == "development_solid")
  {
    const std::string periods = contents(whole / "toner_developed_periods.csv");
    EXPECT_GE(std::count(periods.begin(), periods.end(), '\n'), 4) << periods;
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    EveryMeasurement, MeasurementRestart,
    ::testing::Values(
        Scene{"nip",
              "tests/scenes/nip/kawamoto_nip_inflow.yaml",
              true,
              "--set dem.duration=0.2ms --set dem.settle_time=0.05ms --set nip.average_from=0s "
              "--set dem.checkpoint_interval=0.1ms",
              {"chain_inclination.csv", "brush_height.csv", "flow_report.csv", "nip_profile.csv", "nip_summary.csv", "nip_time_series.csv",
               "summary.csv"}},
        Scene{"development",
              "tests/scenes/development/development_cell.yaml",
              true,
              "--set dem.duration=10us --set development.average_from=0s --set nip.average_from=0s "
              "--set dem.checkpoint_interval=5us",
              {"toner_development.csv", "toner_transfer_profile.csv", "nip_profile.csv", "nip_time_series.csv",
               "summary.csv"}},
        // The developed line over image periods: an image period of 1 um (the drum passes 2.7
        // of them in the 10 us) so that whole periods close before and after the restart. Its
        // state passes through the engine's checkpoint here; too little toner crosses the line
        // in 10 us to count (the counting with toner across a restart: test_developed_line.cpp,
        // test_toner_development.cpp).
        Scene{"development_periods",
              "tests/scenes/development/development_cell.yaml",
              true,
              "--set dem.duration=10us --set development.average_from=0s --set nip.average_from=0s "
              "--set dem.checkpoint_interval=5us --set development.average_over=image_periods "
              "--set electric.image.period=1um --set development.phase_bins=4",
              {"toner_development.csv", "toner_developed_periods.csv", "toner_developed_profile.csv", "summary.csv"}},
        // A solid area: blocks of 0.5 um of drum on the drum's grid (the first, partial one swept
        // and dropped before the restart), counted at both lines (measure_from and measure_to).
        Scene{"development_solid",
              "tests/scenes/development/development_cell.yaml",
              true,
              "--set dem.duration=10us --set development.average_from=0s --set nip.average_from=0s "
              "--set dem.checkpoint_interval=5us --set development.average_over=image_periods "
              "--set electric.image.duty=1 --set electric.image.period=0m --set development.block_length=0.5um "
              "--set development.phase_bins=4",
              {"toner_development.csv", "toner_developed_periods.csv", "toner_developed_periods_at_measure_from.csv",
               "toner_developed_profile.csv", "summary.csv"}},
        Scene{"regulation",
              "cases/kweon_regulation.yaml",
              true,
              "--set dem.duration=0.4ms --set dma.average_from=0s --set dem.checkpoint_interval=0.2ms",
              {"developer_mass_per_area.csv", "flow_report.csv", "summary.csv"}},
        Scene{"release",
              "cases/kweon_release.yaml",
              true,
              "--set dem.duration=0.2ms --set dma.average_from=0s --set dem.checkpoint_interval=0.1ms",
              {"developer_release.csv", "flow_report.csv", "summary.csv"}},
        Scene{"compression",
              "cases/kawamoto_brush_compression.yaml",
              false,
              "--set dem.duration=0.1ms --set compression.map_interval=20us --set dem.checkpoint_interval=50us",
              {"plate_compression.csv", "contact_maps.csv", "contact_map_000.csv", "contact_map_004.csv"}}),
    [](const ::testing::TestParamInfo<Scene> &info) { return std::string(info.param.name); });
