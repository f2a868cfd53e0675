// `magbrush sweep` end to end on a small box scene (two points, DEM only): the summary table
// has the varied value as given and in SI, the steady-state verdict, the run time and status of
// each point; a measured series is compared point by point; a malformed one is refused.
#include "tests/app/run_magbrush.h"
#include "common/study_table.h"

#include "tests/app/sweep_box_case.h"
#include "tests/csv_columns.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace {

namespace fs = std::filesystem;

using magbrush::testing::run_magbrush;
using Result = magbrush::testing::CliRun;

} // namespace

TEST(Sweep, TabulatesEveryPointWithItsSIValueRunTimeAndMeasuredComparison)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep");
  std::ofstream(dir / "box.yaml") << magbrush::testing::sweep_box_case;
  // The box scene has no measurement with a summary; its steady-state verdict is "nan" (nothing
  // tested), which the comparison must carry through as "no verdict".
  std::ofstream(dir / "measured.csv") << "# a measured series\npopulations.carrier.diameter,steady_state\n100um,1\n";
  const Result r = run_magbrush(dir, {"sweep", (dir / "box.yaml").string(), "--vary",
                                      "populations.carrier.diameter=100um,120um", "--skip", "mesh,field,report",
                                      "--set", "output.directory=" + (dir / "out").string(), "--measured",
                                      (dir / "measured.csv").string()});
  ASSERT_EQ(r.status, 0) << r.output;
  const auto rows = magbrush::testing::read_csv_rows(dir / "out" / "sweep_diameter" / "sweep_summary.csv");
  ASSERT_EQ(rows.size(), 3u) << r.output;
  const auto &h = rows[0];
  auto column = [&](const std::string &name) {
    for (std::size_t k = 0; k < h.size(); ++k)
      if (h[k] == name)
        return k;
    ADD_FAILURE() << "no column " << name;
    return std::size_t(0);
  };
  EXPECT_EQ(rows[1][column("populations.carrier.diameter")], "100um");
  EXPECT_DOUBLE_EQ(std::stod(rows[1][column("populations.carrier.diameter [m]")]), 100e-6);
  EXPECT_DOUBLE_EQ(std::stod(rows[2][column("populations.carrier.diameter [m]")]), 120e-6);
  // Keeping the layer: 100 × (100/120)³ = 57.87 → 58 beads at 120 µm.
  EXPECT_EQ(rows[2][column("count")], "58");
  EXPECT_EQ(rows[1][column("steady_state")], "nan");
  EXPECT_EQ(rows[1][column("measured_steady_state")], "1");
  EXPECT_EQ(rows[2][column("measured_steady_state")], "nan"); // no measured value at 120 µm
  EXPECT_EQ(rows[1][column("within_10_percent_steady_state")], "nan");
  EXPECT_GE(std::stod(rows[1][column("run_time_s")]), 0.0);
  EXPECT_EQ(rows[1][column("status")], "ok");

  // A measured file whose header does not name the varied key is refused, saying what it expects.
  std::ofstream(dir / "bad.csv") << "bias,tma_kg_per_m2\n-500V,0.004\n";
  const Result bad = run_magbrush(dir, {"sweep", (dir / "box.yaml").string(), "--vary",
                                        "populations.carrier.diameter=100um", "--skip", "mesh,field,report", "--set",
                                        "output.directory=" + (dir / "out2").string(), "--measured",
                                        (dir / "bad.csv").string()});
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("expected the header 'populations.carrier.diameter,<summary key>'"), std::string::npos)
    << bad.output;
  fs::remove_all(dir);
}

// The stored fields are solved once for the points whose field inputs agree (a drum speed does
// not change the roller field) and once per point where they differ (a pole's strength does):
// one folder per digest under sweep_<NAME>/fields/, and the second point finds its field there.
TEST(Sweep, PointsWithTheSameFieldInputsShareOneSolvedField)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep_fields");
  const std::string roller = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml";
  auto field_folders = [](const fs::path &fields) {
    int n = 0;
    for (const auto &entry : fs::directory_iterator(fields))
      n += entry.is_directory() && fs::exists(entry.path() / "minimal_roller_magnetic.h5");
    return n;
  };
  const Result same = run_magbrush(dir, {"sweep", roller, "--vary", "drum.rpm=-100rpm,-120rpm", "--name", "drum",
                                         "--skip", "mesh,dem,report", "--set",
                                         "output.directory=" + (dir / "out").string()});
  EXPECT_EQ(field_folders(dir / "out" / "sweep_drum" / "fields"), 1) << same.output;
  EXPECT_NE(same.output.find("magnetic field up to date"), std::string::npos) << same.output;

  const Result differ = run_magbrush(dir, {"sweep", roller, "--vary", "roller.poles.N1.strength=150kA/m,160kA/m",
                                           "--name", "pole", "--skip", "mesh,dem,report", "--set",
                                           "output.directory=" + (dir / "out").string()});
  EXPECT_EQ(field_folders(dir / "out" / "sweep_pole" / "fields"), 2) << differ.output;
  EXPECT_EQ(differ.output.find("magnetic field up to date"), std::string::npos) << differ.output;
  // A pole is addressed by its name inside a list inside a section (roller.poles[].strength):
  // the table still knows the value's unit and gives it in SI, the axis of the study's plots.
  const auto rows = magbrush::testing::read_csv_rows(dir / "out" / "sweep_pole" / "sweep_summary.csv");
  ASSERT_EQ(rows.size(), 3u) << differ.output;
  std::size_t si = rows[0].size();
  for (std::size_t k = 0; k < rows[0].size(); ++k)
    if (rows[0][k] == "roller.poles.N1.strength [A/m]")
      si = k;
  ASSERT_LT(si, rows[0].size()) << "no SI column for the pole's strength";
  EXPECT_DOUBLE_EQ(std::stod(rows[1][si]), 150e3);
  EXPECT_DOUBLE_EQ(std::stod(rows[2][si]), 160e3);
  fs::remove_all(dir);
}

// A --with key goes value for value with the first --vary (a TMA study's fog point: the last
// bias again on a dark drum): one point per pair, not every combination, each with both values
// in its row and folder; a --with list of another length is refused, naming both counts.
TEST(Sweep, AWithKeyGoesValueForValueWithTheFirstVary)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep_with");
  const std::string roller = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml";
  const Result r = run_magbrush(dir, {"sweep", roller, "--vary", "drum.rpm=-100rpm,-120rpm,-120rpm", "--with",
                                      "roller.poles.N1.strength=150kA/m,150kA/m,160kA/m", "--name", "zip", "--skip",
                                      "mesh,dem,report", "--set", "output.directory=" + (dir / "out").string()});
  ASSERT_EQ(r.status, 0) << r.output;
  const auto rows = magbrush::testing::read_csv_rows(dir / "out" / "sweep_zip" / "sweep_summary.csv");
  ASSERT_EQ(rows.size(), 4u) << r.output; // three points, not nine
  auto column = [&](const std::string &name) {
    for (std::size_t k = 0; k < rows[0].size(); ++k)
      if (rows[0][k] == name)
        return k;
    ADD_FAILURE() << "no column " << name;
    return std::size_t(0);
  };
  const std::vector<std::pair<double, double>> expected = {{-100.0, 150e3}, {-120.0, 150e3}, {-120.0, 160e3}};
  for (std::size_t n = 0; n < expected.size(); ++n)
  {
    EXPECT_NEAR(std::stod(rows[n + 1][column("drum.rpm [rad/s]")]), expected[n].first * 2.0 * M_PI / 60.0, 1e-7); // printed to 9 digits
    EXPECT_DOUBLE_EQ(std::stod(rows[n + 1][column("roller.poles.N1.strength [A/m]")]), expected[n].second);
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "sweep_zip" / "p2_rpm--120rpm_strength-160kA_m")) << r.output;
  // Two pole strengths: two solved fields for three points.
  int fields = 0;
  for (const auto &entry : fs::directory_iterator(dir / "out" / "sweep_zip" / "fields"))
    fields += entry.is_directory();
  EXPECT_EQ(fields, 2);

  const Result bad = run_magbrush(dir, {"sweep", roller, "--vary", "drum.rpm=-100rpm,-120rpm", "--with",
                                        "roller.poles.N1.strength=150kA/m", "--skip", "mesh,dem,report", "--set",
                                        "output.directory=" + (dir / "out2").string()});
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("gives 1 values; they go value for value with the first --vary (drum.rpm), which has 2"),
            std::string::npos)
    << bad.output;
  fs::remove_all(dir);
}

// A population given by its mass (or supplied by the inflow: count 0) keeps its volume by
// itself when its diameter changes; the sweep must still scale its spread and a fixed time
// step with the diameter (a fed nip at 42 µm otherwise runs at the 60 µm step, above the
// stable limit, and with the 60 µm spread).
TEST(Sweep, ADiameterStudyOfAPopulationGivenByMassScalesItsSpreadAndTheStep)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep_mass");
  std::string box = magbrush::testing::sweep_box_case;
  // 100 beads' mass at 100 µm (2200 kg/m³): 1.152e-7 kg.
  box.replace(box.find("count: 100"), std::string("count: 100").size(), "mass: 1.152e-7 kg, diameter_std: 10 um");
  box.replace(box.find("dem: {"), std::string("dem: {").size(), "dem: {time_step: 40 ns, ");
  std::ofstream(dir / "box.yaml") << box;
  const Result r = run_magbrush(dir, {"sweep", (dir / "box.yaml").string(), "--vary",
                                      "populations.carrier.diameter=100um,50um", "--skip", "mesh,field,dem,report",
                                      "--set", "output.directory=" + (dir / "out").string()});
  ASSERT_EQ(r.status, 0) << r.output;
  // The point's case as it ran: `magbrush run` writes it resolved into the point's folder.
  const fs::path resolved_file = dir / "out" / "sweep_diameter" / "p1_diameter-50um" / "case_resolved.txt";
  ASSERT_TRUE(fs::exists(resolved_file)) << r.output;
  std::ifstream resolved_in(resolved_file);
  const std::string point((std::istreambuf_iterator<char>(resolved_in)), std::istreambuf_iterator<char>());
  auto resolved = [&](const std::string &key) {
    const std::size_t at = point.find("\n" + key + " ");
    if (at == std::string::npos)
      return std::string("(missing)");
    const std::size_t eq = point.find("= ", at);
    return point.substr(eq + 2, point.find('\n', eq) - eq - 2);
  };
  EXPECT_EQ(resolved("populations.carrier.mass"), "115.2 ug") << point.substr(0, 4000);
  EXPECT_EQ(resolved("populations.carrier.count"), "0");
  EXPECT_EQ(resolved("populations.carrier.diameter_std"), "5 um");
  EXPECT_EQ(resolved("dem.time_step"), "20 ns");
  fs::remove_all(dir);
}

// --repeats N runs every point with the seeds seed .. seed + N-1 (the last varied key, so
// that a point's repeats are neighbours) and writes sweep_mean.csv: one row per point, each
// key's mean over its repeats with the standard error of their spread. The runs' summaries
// are written by hand here (the points run no stage), so that the means are known exactly;
// the merge then reads them as it reads a real run's.
TEST(Sweep, RepeatsAreAveragedWithTheStandardErrorOfTheirSpread)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep_repeats");
  std::ofstream(dir / "box.yaml") << magbrush::testing::sweep_box_case;
  const std::vector<std::string> sweep = {"sweep", (dir / "box.yaml").string(), "--vary",
                                          "populations.carrier.diameter=100um,120um", "--repeats", "3", "--skip",
                                          "mesh,field,dem,report", "--set", "output.directory=" + (dir / "out").string()};
  const Result r = run_magbrush(dir, sweep);
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path folder = dir / "out" / "sweep_diameter"; // named by the varied key, not the seeds
  const double tma[2][3] = {{1.0e-4, 2.0e-4, 6.0e-4}, {3.0e-4, 3.0e-4, 3.0e-4}};
  const char *labels[2][3] = {{"p0_diameter-100um_seed-1", "p1_diameter-100um_seed-2", "p2_diameter-100um_seed-3"},
                              {"p3_diameter-120um_seed-1", "p4_diameter-120um_seed-2", "p5_diameter-120um_seed-3"}};
  for (int p = 0; p < 2; ++p)
    for (int k = 0; k < 3; ++k)
    {
      ASSERT_TRUE(fs::exists(folder / labels[p][k])) << labels[p][k] << "\n" << r.output;
      fs::create_directories(folder / labels[p][k] / "dem");
      std::ofstream(folder / labels[p][k] / "dem" / "summary.csv")
        << "key,value,standard_error,drift,drift_standard_error\n"
        << "tma_kg_per_m2," << tma[p][k] << ",1e-9,0.1,0.01\nsteady_state," << (p == 1 || k != 1 ? 1 : 0)
        << ",nan,nan,nan\n";
    }
  std::vector<std::string> merge = sweep;
  merge.push_back("--merge");
  const Result merged = run_magbrush(dir, merge);
  ASSERT_EQ(merged.status, 0) << merged.output;

  EXPECT_EQ(magbrush::testing::read_csv_rows(folder / "sweep_summary.csv").size(), 7u); // every run, with its seed
  auto mean = magbrush::testing::read_csv_columns(folder / "sweep_mean.csv");
  ASSERT_EQ(mean["point"].size(), 2u) << merged.output;
  for (const auto &[name, cells] : mean)
    EXPECT_EQ(name.find("dem.seed"), std::string::npos) << "the seed is not a point's coordinate in the means";
  EXPECT_EQ(mean["point"][0], "p0_diameter-100um");
  EXPECT_EQ(mean["populations.carrier.diameter"], (std::vector<std::string>{"100um", "120um"}));
  EXPECT_EQ(mean["repeats"][0], "3");
  // 1, 2, 6 (e-4): mean 3e-4, standard error √(7/3) e-4 from the spread, not the runs' 1e-9.
  ASSERT_EQ(mean["tma_kg_per_m2_stderr"].size(), 2u) << merged.output;
  EXPECT_NEAR(std::stod(mean["tma_kg_per_m2"][0]), 3.0e-4, 1e-10);
  EXPECT_NEAR(std::stod(mean["tma_kg_per_m2_stderr"][0]), std::sqrt(7.0 / 3.0) * 1e-4, 1e-9);
  EXPECT_NEAR(std::stod(mean["tma_kg_per_m2_stderr"][1]), 0.0, 1e-12);
  EXPECT_NEAR(std::stod(mean["tma_kg_per_m2_drift"][0]), 0.1, 1e-9);
  // One repeat of the first point drifted: the point is not steady; every repeat of the second was.
  EXPECT_EQ(mean["steady_state"], (std::vector<std::string>{"0", "1"}));
  EXPECT_EQ(mean["status"][0], "ok");

  // The seeds are the repeats': varying them as well is refused, as is a repeat count of 0.
  std::vector<std::string> both = sweep;
  both.insert(both.begin() + 4, {"--vary", "dem.seed=4,5"});
  const Result refused = run_magbrush(dir, both);
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.output.find("do not also vary dem.seed"), std::string::npos) << refused.output;
  std::vector<std::string> none = sweep;
  none[5] = "0";
  const Result zero = run_magbrush(dir, none);
  EXPECT_NE(zero.status, 0);
  EXPECT_NE(zero.output.find("--repeats expects a whole number of runs per point"), std::string::npos) << zero.output;
  fs::remove_all(dir);
}
