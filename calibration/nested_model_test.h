// Does a least-squares model with more parameters fit significantly better than a simpler one
// it contains? The F-test for nested models.
//
// The simple model (p₁ parameters, residual sum of squares RSS₁) is the larger one (p₂, RSS₂)
// with some parameters tied together, both fitted to the same n values. If the extra freedom
// only fits noise, (RSS₁ − RSS₂)/(p₂ − p₁) and RSS₂/(n − p₂) both estimate the noise variance,
// and their ratio
//     F = [(RSS₁ − RSS₂)/(p₂ − p₁)] / [RSS₂/(n − p₂)]
// follows the F distribution with (p₂ − p₁, n − p₂) degrees of freedom (independent Gaussian
// noise; the nonlinear models are treated as linear near their optimum). The p-value is the
// chance of an F at least this large from noise alone; a small one means the larger model
// describes something real.
//
// We use it (rather than AIC or BIC) because the two models are nested least-squares fits with
// the noise variance estimated from the data itself, which is exactly the F-test's setting, and
// it answers with a significance level a reader can check. BIC's penalty grows with ln n, so
// its verdict would depend on how densely the scan happens to be sampled.
#pragma once

#include <cstddef>

namespace magbrush {

struct NestedModelTest
{
  double F = 0.0;
  double p_value = 1.0; // P(F ≥ observed | the simpler model is right)
  std::size_t numerator_dof = 0, denominator_dof = 0;
};

NestedModelTest compare_nested_models(double rss_simple, std::size_t parameters_simple,
                                      double rss_larger, std::size_t parameters_larger,
                                      std::size_t values);

// P(X ≥ F) for X ~ F(d1, d2).
double f_distribution_upper_tail(double F, double d1, double d2);

// The regularised incomplete beta function I_x(a, b), x in [0, 1], a, b > 0.
double regularized_incomplete_beta(double x, double a, double b);

} // namespace magbrush
