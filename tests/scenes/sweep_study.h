// What the study regressions (development, regulation, release) share: running `magbrush
// sweep` as a user does, in a fresh folder, and the mass budget of each point's flow report.
#pragma once

#include "tests/csv_columns.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace magbrush::testing {

// Runs `magbrush sweep <arguments> --set output.directory=results` in a new temporary folder
// named `name` (the log in its sweep.log) and returns that folder; fails the test (and returns
// an empty path) when the sweep fails.
inline std::filesystem::path run_sweep_study(const std::string &name, const std::string &arguments)
{
  const std::filesystem::path dir = test_temp_dir(name);
  const std::string cmd = "cd '" + dir.string() + "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '" +
                          std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush' sweep " + arguments +
                          " --set output.directory=results > sweep.log 2>&1";
  const int raw = std::system(cmd.c_str());
  if (!(WIFEXITED(raw) && WEXITSTATUS(raw) == 0))
  {
    ADD_FAILURE() << "magbrush sweep failed: see " << (dir / "sweep.log");
    return {};
  }
  return dir;
}

// Mass conserved to the particle in one flow report: at every row the particles present are
// those present at the start (a prefilled layer, or none) plus those created minus those
// removed, and their masses likewise; and something must have left.
inline void expect_flow_budget_closes(const std::filesystem::path &report)
{
  const auto flow = read_csv_columns(report);
  for (const char *column : {"present", "in", "out", "present_mass_kg", "in_mass_kg", "out_mass_kg"})
    ASSERT_TRUE(flow.count(column)) << report << " has no column " << column;
  const std::size_t rows = flow.at("present").size();
  ASSERT_GT(rows, 100u) << report;
  auto count = [&](const char *column, std::size_t r) { return std::atol(flow.at(column)[r].c_str()); };
  auto mass = [&](const char *column, std::size_t r) { return std::atof(flow.at(column)[r].c_str()); };
  const long initial = count("present", 0) - count("in", 0) + count("out", 0);
  const double initial_mass = mass("present_mass_kg", 0) - mass("in_mass_kg", 0) + mass("out_mass_kg", 0);
  for (std::size_t r = 0; r < rows; ++r)
  {
    ASSERT_EQ(count("present", r), initial + count("in", r) - count("out", r)) << report << " row " << r;
    const double expected = initial_mass + mass("in_mass_kg", r) - mass("out_mass_kg", r);
    // The CSV holds nine digits.
    ASSERT_NEAR(mass("present_mass_kg", r), expected, 1e-7 * (initial_mass + mass("in_mass_kg", r)))
        << report << " row " << r;
  }
  EXPECT_GT(count("out", rows - 1), 0) << report << ": nothing left the scene";
}

// The same for every point of a sweep; returns the number of flow reports found.
inline int expect_flow_budgets_close(const std::filesystem::path &sweep)
{
  int reports = 0;
  for (const auto &entry : std::filesystem::recursive_directory_iterator(sweep))
    if (entry.path().filename() == "flow_report.csv")
    {
      ++reports;
      expect_flow_budget_closes(entry.path());
    }
  return reports;
}

} // namespace magbrush::testing
