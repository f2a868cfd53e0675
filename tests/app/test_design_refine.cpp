// `magbrush design gap --refine` end to end on the box scene of the sweep tests (seconds): a
// finished three-point study over the carrier diameter, its bead count (which the sweep
// scales as (100 µm / d)³ to keep the layer) as the quantity, inverted by the weighted line.
// One extra point is run as a point of the study itself: the table gains a fourth row, named
// and numbered after the earlier three, whose rows stay as they were; the new point's count is
// the layer-keeping count of its own diameter (derived afresh, not the first point's copied).
#include "tests/app/run_magbrush.h"
#include "tests/app/sweep_box_case.h"
#include "tests/csv_columns.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;
using magbrush::testing::run_magbrush;

TEST(DesignRefine, RunsTheNarrowingPointAsAPointOfTheStudy)
{
  const fs::path dir = magbrush::testing::test_temp_dir("app_design_refine");
  std::ofstream(dir / "box.yaml") << magbrush::testing::sweep_box_case;
  const auto sweep = run_magbrush(dir, {"sweep", (dir / "box.yaml").string(), "--vary",
                                        "populations.carrier.diameter=80um,100um,120um", "--skip", "mesh,field,report",
                                        "--set", "output.directory=" + (dir / "out").string()});
  ASSERT_EQ(sweep.status, 0) << sweep.output;
  const fs::path study = dir / "out" / "sweep_diameter";
  const auto before = magbrush::testing::read_csv_rows(study / "sweep_summary.csv");
  ASSERT_EQ(before.size(), 4u);

  const auto r = run_magbrush(dir, {"design", "gap", study.string(), "--key", "populations.carrier.diameter",
                                    "--quantity", "count", "--target", "120", "--method", "line", "--tolerance",
                                    "0.1um", "--refine", "--max-points", "1", "--skip", "mesh,field,report"});
  EXPECT_EQ(r.status, 4) << r.output; // one point allowed, the interval still wider than 0.1 µm
  EXPECT_NE(r.output.find("--point 3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--merge"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(4 points)"), std::string::npos) << r.output;

  const auto after = magbrush::testing::read_csv_rows(study / "sweep_summary.csv");
  ASSERT_EQ(after.size(), 5u) << r.output;
  for (size_t k = 0; k < before.size(); ++k)
    EXPECT_EQ(after[k], before[k]) << "row " << k;
  const auto &h = after[0];
  auto column = [&](const std::string &name) {
    for (size_t k = 0; k < h.size(); ++k)
      if (h[k] == name)
        return k;
    ADD_FAILURE() << "no column " << name;
    return size_t(0);
  };
  const auto &row = after[4];
  EXPECT_EQ(row[column("point")].rfind("p3_diameter-", 0), 0u) << row[column("point")];
  EXPECT_EQ(row[column("status")], "ok");
  const double d = std::stod(row[column("populations.carrier.diameter [m]")]);
  EXPECT_GT(d, 80e-6);
  EXPECT_LT(d, 120e-6);
  EXPECT_EQ(std::stol(row[column("count")]), std::lround(100.0 * std::pow(100e-6 / d, 3)));
  EXPECT_TRUE(fs::exists(study / row[column("point")] / "variant.txt"));
  fs::remove_all(dir);
}

} // namespace
