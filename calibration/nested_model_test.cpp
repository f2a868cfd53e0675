// The F-test for nested least-squares models (see nested_model_test.h).
#include "calibration/nested_model_test.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace magbrush {

namespace {

// The continued fraction of I_x(a, b) (modified Lentz's method), which converges quickly for
// x < (a + 1)/(a + b + 2); the caller uses the symmetry I_x(a, b) = 1 − I_{1−x}(b, a) otherwise.
double incomplete_beta_fraction(double x, double a, double b)
{
  constexpr double tiny = 1e-300, eps = 1e-15;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::abs(d) < tiny)
    d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 10000; ++m)
  {
    const double m2 = 2.0 * m;
    // Even step.
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    d = std::abs(d) < tiny ? tiny : d;
    c = 1.0 + aa / c;
    c = std::abs(c) < tiny ? tiny : c;
    d = 1.0 / d;
    h *= d * c;
    // Odd step.
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    d = std::abs(d) < tiny ? tiny : d;
    c = 1.0 + aa / c;
    c = std::abs(c) < tiny ? tiny : c;
    d = 1.0 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < eps)
      return h;
  }
  return h; // not reached for the arguments used here
}

} // namespace

double regularized_incomplete_beta(double x, double a, double b)
{
  if (!(a > 0.0 && b > 0.0) || x < 0.0 || x > 1.0)
    throw std::invalid_argument("regularized_incomplete_beta: needs a, b > 0 and x in [0, 1]");
  if (x == 0.0 || x == 1.0)
    return x;
  // x^a (1−x)^b / (a B(a, b)), in logarithms to stay finite for large a, b.
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                           a * std::log(x) + b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0))
    return std::exp(log_front) * incomplete_beta_fraction(x, a, b) / a;
  return 1.0 - std::exp(log_front) * incomplete_beta_fraction(1.0 - x, b, a) / b;
}

double f_distribution_upper_tail(double F, double d1, double d2)
{
  if (!(F > 0.0))
    return 1.0;
  return regularized_incomplete_beta(d2 / (d2 + d1 * F), 0.5 * d2, 0.5 * d1);
}

NestedModelTest compare_nested_models(double rss_simple, std::size_t parameters_simple,
                                      double rss_larger, std::size_t parameters_larger,
                                      std::size_t values)
{
  if (parameters_larger <= parameters_simple || values <= parameters_larger)
    throw std::invalid_argument("compare_nested_models: needs p_simple < p_larger < n");
  NestedModelTest t;
  t.numerator_dof = parameters_larger - parameters_simple;
  t.denominator_dof = values - parameters_larger;
  if (!(rss_larger > 0.0)) // an exact fit of the larger model: the simpler one is rejected
  {
    t.F = rss_simple > 0.0 ? INFINITY : 0.0;
    t.p_value = rss_simple > 0.0 ? 0.0 : 1.0;
    return t;
  }
  t.F = std::max(0.0, (rss_simple - rss_larger) / double(t.numerator_dof)) /
        (rss_larger / double(t.denominator_dof));
  t.p_value = f_distribution_upper_tail(t.F, double(t.numerator_dof), double(t.denominator_dof));
  return t;
}

} // namespace magbrush
