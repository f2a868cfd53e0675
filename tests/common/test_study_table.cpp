// The table of a study (common/study_table.h): the union of the points' summary keys, standard
// errors where there are any, the measured comparison with its relative error and flag.
#include "common/study_table.h"

#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace magbrush;

namespace {
constexpr double no_value = std::numeric_limits<double>::quiet_NaN();

std::vector<std::vector<std::string>> parse(const std::string &csv)
{
  std::vector<std::vector<std::string>> rows;
  std::stringstream in(csv);
  std::string line;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    std::vector<std::string> cells;
    std::stringstream l(line);
    std::string c;
    while (std::getline(l, c, ','))
      cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}
} // namespace

TEST(StudyTable, ColumnsAreTheUnionOfTheSummariesWithStandardErrorsWhereGiven)
{
  std::vector<StudyPoint> points = {
      {"p0", {"-500V"}, {{"tma_kg_per_m2", 2.0e-3, 1e-4}, {"fog_kg_per_m2", 1e-5, no_value}}, {"12.5", "ok"}},
      {"p1", {"-600V"}, {{"tma_kg_per_m2", 3.0e-3, no_value}, {"q_over_m_C_per_kg", -0.03, 0.001}}, {"13", "failed"}}};
  const auto rows = parse(study_table_csv("a study", {"electric.bias"}, {"run_time_s", "status"}, points));
  ASSERT_EQ(rows.size(), 3u);
  const std::vector<std::string> header = {"point", "electric.bias", "tma_kg_per_m2", "tma_kg_per_m2_stderr",
                                           "fog_kg_per_m2", "q_over_m_C_per_kg", "q_over_m_C_per_kg_stderr",
                                           "run_time_s", "status"};
  EXPECT_EQ(rows[0], header);
  EXPECT_EQ(rows[1], (std::vector<std::string>{"p0", "-500V", "0.002", "0.0001", "1e-05", "nan", "nan", "12.5", "ok"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{"p1", "-600V", "0.003", "nan", "nan", "-0.03", "0.001", "13", "failed"}));
}

// A key that a point tested for steady state gets its drift and the drift's standard error
// (so that a plot can judge that key alone); points that did not test it read nan.
TEST(StudyTable, DriftColumnsWhereAPointTestedTheKey)
{
  std::vector<StudyPoint> points = {{"p0", {}, {{"dma_kg_per_m2", 0.5, 0.01, 0.002, 0.01}}, {}},
                                    {"p1", {}, {{"dma_kg_per_m2", 0.3, 0.01}}, {}}};
  const auto rows = parse(study_table_csv("", {}, {}, points));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"point", "dma_kg_per_m2", "dma_kg_per_m2_stderr", "dma_kg_per_m2_drift",
                                                "dma_kg_per_m2_drift_stderr"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"p0", "0.5", "0.01", "0.002", "0.01"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{"p1", "0.3", "0.01", "nan", "nan"}));
}

TEST(StudyTable, MeasuredComparisonGivesRelativeErrorAndTheTenPercentFlag)
{
  std::vector<StudyPoint> points = {{"p0", {}, {{"dma_kg_per_m2", 0.50, 0.01}}, {}},
                                    {"p1", {}, {{"dma_kg_per_m2", 0.80, 0.01}}, {}},
                                    {"p2", {}, {{"dma_kg_per_m2", 0.90, 0.01}}, {}}};
  MeasuredComparison m{"dma_kg_per_m2", {0.55, 0.70, no_value}, 0.10};
  const auto rows = parse(study_table_csv("", {}, {}, points, m));
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0][4], "relative_error_dma_kg_per_m2");
  EXPECT_EQ(rows[0][5], "within_10_percent_dma_kg_per_m2");
  EXPECT_NEAR(std::stod(rows[1][4]), 0.50 / 0.55 - 1.0, 1e-5); // −9.1 %: within
  EXPECT_EQ(rows[1][5], "1");
  EXPECT_NEAR(std::stod(rows[2][4]), 0.80 / 0.70 - 1.0, 1e-5); // +14.3 %: not within
  EXPECT_EQ(rows[2][5], "0");
  EXPECT_EQ(rows[3][3], "nan"); // no measured value at this point: no verdict
  EXPECT_EQ(rows[3][5], "nan");
}

TEST(StudyTable, ReadsARunSummaryFile)
{
  const auto dir = magbrush::testing::test_temp_dir("study_table");
  const auto path = dir / "summary.csv";
  std::ofstream(path) << "# comment\nkey,value,standard_error,drift,unit,meaning,measurement,drift_standard_error\n"
                         "normal_force_per_length_N_m,2.5,0.1,0.01,N/m,normal force,nip profile,0.004\n"
                         "peak_normal_pressure_Pa,1400,nan,nan,Pa,peak,nip profile,nan\n"
                         "steady_state,1,nan,nan,1,all steady,run,nan\n";
  const auto rows = read_summary_csv(path.string());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].key, "normal_force_per_length_N_m");
  EXPECT_EQ(rows[0].value, 2.5);
  EXPECT_EQ(rows[0].standard_error, 0.1);
  EXPECT_EQ(rows[0].drift, 0.01);
  EXPECT_EQ(rows[0].drift_standard_error, 0.004);
  EXPECT_TRUE(std::isnan(rows[1].standard_error));
  EXPECT_TRUE(std::isnan(rows[1].drift));
  EXPECT_EQ(rows[2].key, "steady_state");
  EXPECT_TRUE(read_summary_csv((dir / "absent.csv").string()).empty());
  std::filesystem::remove_all(dir);
}
