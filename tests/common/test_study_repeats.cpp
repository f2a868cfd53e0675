// The mean of a study point's repeats (common/study_repeats.h): the standard error from the
// spread between the repeats (not from their own errors), drifts averaged with their errors
// combined, the run's verdicts combined rather than averaged, a failed repeat left out.
#include "common/study_repeats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace magbrush;

namespace {
constexpr double no_value = std::numeric_limits<double>::quiet_NaN();

const SummaryRow &row(const std::vector<SummaryRow> &rows, const std::string &key)
{
  for (const auto &r : rows)
    if (r.key == key)
      return r;
  static const SummaryRow none{"", no_value, no_value};
  ADD_FAILURE() << "no row " << key;
  return none;
}
} // namespace

TEST(StudyRepeats, StandardErrorComesFromTheSpreadBetweenRepeats)
{
  // Three repeats of 1, 2, 6 with tiny own errors: mean 3, sample std √7, se √7/√3.
  const std::vector<std::vector<SummaryRow>> repeats = {{{"tma_kg_per_m2", 1.0, 1e-6, 0.10, 0.02}},
                                                        {{"tma_kg_per_m2", 2.0, 1e-6, 0.20, 0.02}},
                                                        {{"tma_kg_per_m2", 6.0, 1e-6, 0.30, 0.02}}};
  const auto m = mean_of_repeats(repeats);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_DOUBLE_EQ(m[0].value, 3.0);
  EXPECT_NEAR(m[0].standard_error, std::sqrt(7.0 / 3.0), 1e-12);
  EXPECT_NEAR(m[0].drift, 0.2, 1e-12);
  EXPECT_NEAR(m[0].drift_standard_error, std::sqrt(3 * 0.02 * 0.02) / 3.0, 1e-12);
}

TEST(StudyRepeats, OneRepeatHasNoSpreadAndAFailedRepeatDoesNotCount)
{
  const auto one = mean_of_repeats({{{"fog_kg_per_m2", 4.0, 0.5}}});
  EXPECT_DOUBLE_EQ(one[0].value, 4.0);
  EXPECT_TRUE(std::isnan(one[0].standard_error)); // not the run's own 0.5: that is another error

  // The second repeat failed (no summary rows): the mean is of the two that ran.
  const auto two = mean_of_repeats({{{"tma_kg_per_m2", 2.0, no_value}}, {}, {{"tma_kg_per_m2", 4.0, no_value}}});
  EXPECT_DOUBLE_EQ(two[0].value, 3.0);
  EXPECT_NEAR(two[0].standard_error, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(two[0].drift));
}

TEST(StudyRepeats, VerdictsAreCombinedNotAveraged)
{
  auto run = [](double steady, double trend, double resolution) {
    return std::vector<SummaryRow>{{"steady_state", steady, no_value},
                                   {"significant_drift", trend, no_value},
                                   {"drift_resolution", resolution, no_value}};
  };
  const auto all_steady = mean_of_repeats({run(1, 0, 0.01), run(1, 0, 0.03)});
  EXPECT_EQ(row(all_steady, "steady_state").value, 1.0);
  EXPECT_EQ(row(all_steady, "significant_drift").value, 0.0);
  EXPECT_EQ(row(all_steady, "drift_resolution").value, 0.03);
  EXPECT_TRUE(std::isnan(row(all_steady, "steady_state").standard_error));

  const auto one_drifting = mean_of_repeats({run(1, 0, 0.01), run(0, 1, 0.02), run(1, 0, 0.01)});
  EXPECT_EQ(row(one_drifting, "steady_state").value, 0.0);
  EXPECT_EQ(row(one_drifting, "significant_drift").value, 1.0);

  // A repeat without a verdict leaves the point without one (not "steady").
  const auto undecided = mean_of_repeats({run(1, 0, 0.01), run(no_value, no_value, no_value)});
  EXPECT_TRUE(std::isnan(row(undecided, "steady_state").value));
}
