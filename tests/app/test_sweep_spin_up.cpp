// `magbrush sweep --spin-up --settle` end to end on the small box scene: the spin-up runs once
// and is reused, every point forks from its checkpoint and records which spin-up it came from,
// the points' averages start after the settle, and a point whose values are the spin-up's own
// continues the state bit for bit (its last row equals an uninterrupted run's, and its series
// starts after the fork): the fork is a restart, not a new start.
#include "tests/app/run_magbrush.h"

#include "tests/app/sweep_box_case.h"
#include "tests/csv_columns.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;

using magbrush::testing::run_magbrush;
using Result = magbrush::testing::CliRun;

std::string last_line(const fs::path &file)
{
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty())
      last = line;
  return last;
}

std::string cell(const std::vector<std::vector<std::string>> &rows, const std::string &name)
{
  for (std::size_t k = 0; k < rows[0].size(); ++k)
    if (rows[0][k] == name)
      return rows.at(1).at(k);
  ADD_FAILURE() << "no column " << name;
  return "";
}

} // namespace

TEST(SweepSpinUp, EveryPointForksFromOneSpinUpAndAveragesAfterTheSettle)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_sweep_spin_up");
  std::ofstream(dir / "box.yaml") << magbrush::testing::sweep_box_case;
  const std::vector<std::string> sweep = {"sweep", (dir / "box.yaml").string(), "--vary",
                                          "materials.carrier.friction=0.45,0.2", "--name", "fork", "--skip",
                                          "mesh,field,report", "--set", "output.directory=" + (dir / "out").string(),
                                          "--threads", "1", "--spin-up", "10us", "--settle", "3us"};
  const Result r = run_magbrush(dir, sweep);
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path out = dir / "out" / "sweep_fork";
  ASSERT_TRUE(fs::exists(out / "spin_up" / "dem" / "checkpoint.bin")) << r.output;
  ASSERT_TRUE(fs::exists(out / "spin_up" / "spin_up.csv")) << r.output;

  for (const char *point : {"p0_friction-0.45", "p1_friction-0.2"})
  {
    const auto rows = magbrush::testing::read_csv_rows(out / point / "sweep_point.csv");
    ASSERT_EQ(rows.size(), 2u) << point;
    EXPECT_EQ(cell(rows, "status"), "ok") << point;
    EXPECT_EQ(fs::path(cell(rows, "spin_up")), out / "spin_up") << point;
    EXPECT_DOUBLE_EQ(std::stod(cell(rows, "spin_up_end_s")), 10e-6) << point;
    EXPECT_DOUBLE_EQ(std::stod(cell(rows, "averages_from_s")), 13e-6) << point;
    EXPECT_FALSE(cell(rows, "spin_up_case_digest").empty()) << point;
    // Its DEM restarted from the spin-up's checkpoint with the averages moved to the settle's end.
    std::ifstream log(out / point / "dem" / "dem.log");
    std::ostringstream text;
    text << log.rdbuf();
    EXPECT_NE(text.str().find("restarted from '" + (out / "spin_up" / "dem" / "checkpoint.bin").string() + "'"),
              std::string::npos)
      << point;
    EXPECT_NE(text.str().find("development.average_from"), std::string::npos) << point;
  }

  // The point at the spin-up's own values is its uninterrupted continuation, bit for bit.
  const Result whole = run_magbrush(dir, {"run", (dir / "box.yaml").string(), "--skip", "mesh,field,report", "--set",
                                      "output.directory=" + (dir / "whole").string(), "--threads", "1"});
  ASSERT_EQ(whole.status, 0) << whole.output;
  const std::string uninterrupted = last_line(dir / "whole" / "dem" / "time_series.csv");
  ASSERT_FALSE(uninterrupted.empty());
  EXPECT_EQ(last_line(out / "p0_friction-0.45" / "dem" / "time_series.csv"), uninterrupted);
  // And it did continue (it was not run again from the start): its series begins after the fork.
  const auto series = magbrush::testing::read_csv_rows(out / "p0_friction-0.45" / "dem" / "time_series.csv");
  ASSERT_GE(series.size(), 2u);
  EXPECT_GT(std::stod(series[1][1]), 10e-6);

  // A second sweep with the same case reuses the spin-up.
  const Result again = run_magbrush(dir, sweep);
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("is done: every point forks from it"), std::string::npos) << again.output;
  EXPECT_EQ(again.output.find("##### magbrush sweep: the spin-up"), std::string::npos) << again.output;

  // Without a settle the sweep refuses, saying what the speeds give; a fork past the run's end too.
  std::vector<std::string> no_settle(sweep.begin(), sweep.end() - 4);
  no_settle.insert(no_settle.end(), {"--spin-up", "10us"});
  const Result refused = run_magbrush(dir, no_settle);
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.output.find("--spin-up needs --settle"), std::string::npos) << refused.output;
  std::vector<std::string> too_late(sweep.begin(), sweep.end() - 4);
  too_late.insert(too_late.end(), {"--spin-up", "15us", "--settle", "5us"});
  const Result late = run_magbrush(dir, too_late);
  EXPECT_NE(late.status, 0);
  EXPECT_NE(late.output.find("leave nothing to average"), std::string::npos) << late.output;
  fs::remove_all(dir);
}
