// The inverse of a finished study (design/study_inverse.h) on synthetic sweep tables written
// as `magbrush sweep` writes them:
//  * a linear study: the piecewise and the line answers are the known gap, and the propagated
//    standard error matches the spread of the answer over many noisy copies of the study;
//  * the DMA study of docs/regulation.md (30 ms): the gap for 0.40 kg/m² with its interval;
//  * non-monotone means fall back to the weighted line; a target outside the study is said
//    to be outside; failed points are skipped with a note;
//  * the command (`magbrush design gap`) end to end: answer, exit status 0, and 3 outside.
#include "design/study_inverse.h"
#include "tests/cli_run.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace magbrush;

namespace {

struct Row
{
  double gap_mm, dma, se;
  std::string status = "ok";
};

// sweep_summary.csv of a gap study, as the sweep writes it.
std::string write_study(const std::filesystem::path &dir, const std::vector<Row> &rows)
{
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "sweep_summary.csv").string();
  std::ofstream out(path);
  out << "# magbrush sweep of cases/kweon_regulation.yaml\n"
      << "point,blades.doctor.gap,blades.doctor.gap [m],count,dma_kg_per_m2,dma_kg_per_m2_stderr,"
         "dma_kg_per_m2_drift,run_time_s,status\n";
  for (size_t k = 0; k < rows.size(); ++k)
    out << "p" << k << "_gap-" << rows[k].gap_mm << "mm," << rows[k].gap_mm << "mm," << rows[k].gap_mm * 1e-3
        << ",4000," << rows[k].dma << "," << rows[k].se << ",0.01,400," << rows[k].status << "\n";
  return path;
}

// DMA = 0.05 + 1200 kg/m³ × gap, standard error 0.005 at every point.
std::vector<Row> linear_rows()
{
  return {{0.3, 0.41, 0.005}, {0.4, 0.53, 0.005}, {0.5, 0.65, 0.005}, {0.6, 0.77, 0.005}};
}

TEST(StudyInverse, LinearStudyGivesTheKnownGapBothWays)
{
  const auto tmp = magbrush::testing::test_temp_dir("study_inverse");
  const auto table = read_study_table(write_study(tmp, linear_rows()), "blades.doctor.gap", "dma_kg_per_m2");
  ASSERT_EQ(table.points.size(), 4u);
  EXPECT_EQ(table.case_path, "cases/kweon_regulation.yaml");
  const auto piecewise = invert_study(table, 0.44);
  EXPECT_EQ(piecewise.method, StudyAnswer::Method::piecewise);
  EXPECT_NEAR(piecewise.x, 0.325e-3, 1e-12);
  // (Δx/Δy) √((1 − t)² + t²) σ with t = 1/4
  EXPECT_NEAR(piecewise.se, 1e-4 / 0.12 * 0.005 * std::sqrt(0.5625 + 0.0625), 1e-12);
  const auto line = invert_study(table, 0.44, StudyAnswer::Method::line);
  EXPECT_NEAR(line.x, 0.325e-3, 1e-12);
  EXPECT_NEAR(line.slope, 1200.0, 1e-6);
  EXPECT_TRUE(piecewise.inside);
  std::printf("linear study, target 0.44 kg/m²: piecewise %.4f ± %.4f mm, line %.4f ± %.4f mm\n",
              piecewise.x * 1e3, piecewise.se * 1e3, line.x * 1e3, line.se * 1e3);
}

// The propagated standard error against the spread of the answers over noisy studies.
TEST(StudyInverse, PropagatedErrorMatchesTheSpreadOfNoisyStudies)
{
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto rows = linear_rows();
  for (auto method : {StudyAnswer::Method::piecewise, StudyAnswer::Method::line})
  {
    double sum = 0, sum2 = 0, stated = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k)
    {
      StudyTable t;
      for (const auto &r : rows)
        t.points.push_back({"p", r.gap_mm * 1e-3, r.dma + r.se * noise(rng), r.se});
      const auto a = invert_study(t, 0.44, method);
      sum += a.x;
      sum2 += a.x * a.x;
      stated += a.se / n;
    }
    const double spread = std::sqrt(sum2 / n - (sum / n) * (sum / n));
    std::printf("%s: stated standard error %.3f um, spread of 20000 noisy studies %.3f um\n",
                method == StudyAnswer::Method::line ? "line" : "piecewise", stated * 1e6, spread * 1e6);
    // The line's stated error is rescaled by √(χ²/dof) when that exceeds 1 (the line missing
    // the points by more than their errors): conservative by E[√max(1, χ²₂/2)] ≈ 1.13 here.
    if (method == StudyAnswer::Method::piecewise)
      EXPECT_NEAR(stated / spread, 1.0, 0.03);
    else
    {
      EXPECT_GT(stated / spread, 0.97);
      EXPECT_LT(stated / spread, 1.20);
    }
  }
}

TEST(StudyInverse, RegulationStudyGapForTheTarget)
{
  // docs/regulation.md, the study at 30 ms: DMA areal against the gap.
  const auto tmp = magbrush::testing::test_temp_dir("study_inverse");
  const auto table = read_study_table(
      write_study(tmp, {{0.3, 0.184, 0.005}, {0.4, 0.310, 0.007}, {0.5, 0.429, 0.004}, {0.6, 0.538, 0.002}}),
      "blades.doctor.gap", "dma_kg_per_m2");
  const auto a = invert_study(table, 0.40);
  std::printf("regulation study, 0.40 kg/m²: gap %.4f ± %.4f mm (%s)\n", a.x * 1e3, a.se * 1e3, a.how.c_str());
  const double t = (0.40 - 0.310) / (0.429 - 0.310);
  EXPECT_NEAR(a.x, (0.4 + 0.1 * t) * 1e-3, 1e-12);
  EXPECT_NEAR(a.se, 1e-4 / 0.119 * std::hypot((1 - t) * 0.007, t * 0.004), 1e-12);
}

TEST(StudyInverse, NonMonotoneOutsideAndFailedPoints)
{
  const auto tmp = magbrush::testing::test_temp_dir("study_inverse");
  auto rows = linear_rows();
  rows[2].dma = 0.50; // below the point before it: noise larger than the step
  rows.push_back({0.7, 0.9, 0.005, "failed"});
  const auto table = read_study_table(write_study(tmp, rows), "blades.doctor.gap", "dma_kg_per_m2");
  EXPECT_EQ(table.points.size(), 4u);
  ASSERT_EQ(table.notes.size(), 1u);
  EXPECT_NE(table.notes[0].find("failed"), std::string::npos);
  const auto a = invert_study(table, 0.44);
  EXPECT_FALSE(a.monotone);
  EXPECT_EQ(a.method, StudyAnswer::Method::line);
  const auto outside = invert_study(table, 0.95);
  EXPECT_FALSE(outside.inside);
  EXPECT_NE(outside.how.find("EXTRAPOLATED"), std::string::npos);
}

TEST(StudyInverse, CommandAnswersAndSaysWhenOutside)
{
  const auto tmp = magbrush::testing::test_temp_dir("study_inverse");
  write_study(tmp, linear_rows());
  const auto in = magbrush::testing::run_program("magbrush", "design gap --target 0.44kg/m2 '" + tmp.string() + "'");
  EXPECT_EQ(in.code, 0) << in.output;
  EXPECT_NE(in.output.find("blades.doctor.gap = 0.3250 mm ± 0.0033 mm"), std::string::npos) << in.output;
  const auto out = magbrush::testing::run_program("magbrush", "design gap --target 0.9kg/m2 '" + tmp.string() + "'");
  EXPECT_EQ(out.code, 3) << out.output;
  EXPECT_NE(out.output.find("OUTSIDE"), std::string::npos) << out.output;
}

} // namespace
