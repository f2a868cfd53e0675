// Verification of the active study's choice of its next point (design/study_refinement.h),
// against closed forms written out here independently of the code:
//  * the piecewise inverse: the answer's error with a point c added between the bracket's two
//    (|Δx/Δy| · hypot((1 − t)σ, t σ') over the new piece), scanned on a fine grid; the chosen
//    point reaches that minimum, lies on the study's line and leans towards the better-known
//    neighbour;
//  * two points of equal error and the target midway: no point narrows the answer (one run's
//    error is larger than the mean of two), so the gain is not positive;
//  * the weighted line: the error of the prediction at x* after adding a point (the update of
//    the line's covariance by one observation), scanned;
//  * a target outside the study is refused.
#include "design/study_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace magbrush;

namespace {

StudyTable table_of(const std::vector<StudySample> &points)
{
  StudyTable t;
  t.x_key = "x";
  t.y_key = "y";
  t.points = points;
  return t;
}

TEST(StudyRefinement, PiecewiseReachesTheClosedFormMinimumAndLeansToTheBetterKnownPoint)
{
  // y = 2x; x = 0 known to ±0.02, x = 1 to ±0.002; target y = 1 → x* = 0.5.
  const StudyTable t = table_of({{"a", 0.0, 0.0, 0.02}, {"b", 1.0, 2.0, 0.002}});
  const RefinementPlan p = plan_refinement(t, 1.0, StudyAnswer::Method::piecewise, 2001);
  // The closed form: a point c with σ_c interpolated between the two.
  auto se_with = [](double c) {
    const double sc = 0.02 + c * (0.002 - 0.02);
    if (c <= 0.5) // new piece [c, 1]
    {
      const double tt = (1.0 - 2 * c) / (2.0 - 2 * c);
      return 0.5 * std::hypot((1 - tt) * sc, tt * 0.002);
    }
    const double tt = 1.0 / (2 * c); // new piece [0, c]
    return 0.5 * std::hypot((1 - tt) * 0.02, tt * sc);
  };
  double best = 1e9, at = 0;
  for (int k = 1; k < 100000; ++k)
    if (se_with(k * 1e-5) < best)
    {
      best = se_with(k * 1e-5);
      at = k * 1e-5;
    }
  std::printf("piecewise: se %.6f → %.6f at x = %.4f (closed form %.6f at %.4f)\n", p.se_now, p.se_after, p.x, best,
              at);
  EXPECT_NEAR(p.se_now, 0.5 * std::hypot(0.5 * 0.02, 0.5 * 0.002), 1e-15);
  EXPECT_NEAR(p.se_after, best, 1e-6 * best + 1e-9);
  EXPECT_NEAR(p.x, at, 1e-3);
  EXPECT_GT(p.x, 0.5); // towards the better-known point at x = 1
  EXPECT_NEAR(p.predicted_y, 2 * p.x, 1e-12);
  EXPECT_NEAR(p.predicted_se, 0.02 + p.x * (0.002 - 0.02), 1e-12);
  EXPECT_GT(p.gain(), 0.1);
}

TEST(StudyRefinement, NoPointNarrowsTheMeanOfTwoEqualPoints)
{
  const StudyTable t = table_of({{"a", 0.0, 0.0, 0.01}, {"b", 1.0, 2.0, 0.01}});
  const RefinementPlan p = plan_refinement(t, 1.0, StudyAnswer::Method::piecewise);
  std::printf("equal points, target midway: se %.6f → %.6f (gain %.3f)\n", p.se_now, p.se_after, p.gain());
  EXPECT_LE(p.gain(), 1e-9);
}

TEST(StudyRefinement, LineReachesTheMinimumOfTheUpdatedCovariance)
{
  // y = 1 + 3x at x = 0..3, ±0.1 each; target y = 3.4 → x* = 0.8.
  const StudyTable t = table_of({{"a", 0, 1, 0.1}, {"b", 1, 4, 0.1}, {"c", 2, 7, 0.1}, {"d", 3, 10, 0.1}});
  const RefinementPlan p = plan_refinement(t, 3.4, StudyAnswer::Method::line, 3001);
  // The line's covariance C = σ² (XᵀX)⁻¹; one observation at c with error σ updates the
  // variance of ŷ(x*) by −(hᵀ C h0)² / (σ² + hᵀ C h), h = (1, c), h0 = (1, x*); x's error is
  // that over |slope| (the points lie on the line: χ² = 0, no scaling).
  const double s2 = 0.01, n = 4, sx = 6, sxx = 14, det = n * sxx - sx * sx;
  const double C00 = s2 * sxx / det, C01 = -s2 * sx / det, C11 = s2 * n / det;
  auto quad = [&](double u, double v) { return C00 + C01 * (u + v) + C11 * u * v; }; // (1,u) C (1,v)
  const double v0 = quad(0.8, 0.8);
  double best = 1e9;
  for (int k = 1; k < 30000; ++k)
  {
    const double c = k * 1e-4;
    best = std::min(best, std::sqrt(v0 - std::pow(quad(c, 0.8), 2) / (s2 + quad(c, c))) / 3.0);
  }
  std::printf("line: se %.6f → %.6f at x = %.4f (closed form %.6f)\n", p.se_now, p.se_after, p.x, best);
  EXPECT_NEAR(p.se_now, std::sqrt(v0) / 3.0, 1e-12);
  EXPECT_NEAR(p.se_after, best, 1e-4 * best);
  EXPECT_NEAR(p.predicted_y, 1 + 3 * p.x, 1e-12);
}

TEST(StudyRefinement, RefusesATargetOutsideTheStudy)
{
  const StudyTable t = table_of({{"a", 0.0, 0.0, 0.01}, {"b", 1.0, 2.0, 0.01}});
  EXPECT_THROW(plan_refinement(t, 3.0), std::invalid_argument);
}

} // namespace
