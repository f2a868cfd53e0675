// Block-averaged standard errors and the steady-state drift (dem/measurements/sample_series.h)
// against exact results: the drift of a linear ramp, and the standard error of the mean of a
// correlated AR(1) series, whose exact value the naive σ/√n misses by a factor 4.4.
#include "dem/measurements/sample_series.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using magbrush::dem::SampleSeries;

TEST(SampleSeries, DriftOfALinearRampIsExact)
{
  // v = 1 + a t on n equal steps over [0, 1): the halves' means are 1 + a/4 and 1 + 3a/4 up to
  // the discretisation, exactly (1 + a(n/2 − 1)/(2n)) and (1 + a(3n/2 − 1)/(2n)).
  const int n = 1000;
  const double a = 0.1;
  SampleSeries s;
  for (int k = 0; k < n; ++k)
    s.add(1.0 + a * k / n);
  const double m = 1.0 + a * (n - 1) / (2.0 * n);
  EXPECT_NEAR(s.mean(), m, 1e-14);
  EXPECT_NEAR(s.drift(), (a / 2.0) / m, 1e-13);
  EXPECT_GT(s.drift(), 0.02); // a 10 % ramp is not a steady state
}

TEST(SampleSeries, ConstantSeriesHasNoDriftAndNoError)
{
  SampleSeries s;
  for (int k = 0; k < 100; ++k)
    s.add(3.5);
  EXPECT_DOUBLE_EQ(s.mean(), 3.5);
  EXPECT_EQ(s.drift(), 0.0);
  EXPECT_EQ(s.standard_error(), 0.0);
}

TEST(SampleSeries, TooFewSamplesGiveNaNRatherThanANumber)
{
  SampleSeries s;
  for (int k = 0; k < 15; ++k)
    s.add(k);
  EXPECT_TRUE(std::isnan(s.standard_error())); // 10 blocks need 20 samples
  EXPECT_FALSE(std::isnan(s.standard_error(5)));
  SampleSeries three;
  for (int k = 0; k < 3; ++k)
    three.add(k + 1.0);
  EXPECT_TRUE(std::isnan(three.drift()));
}

TEST(SampleSeries, BlockStandardErrorOfACorrelatedSeriesMatchesTheExactValue)
{
  // x_t = ρ x_{t−1} + ε_t, ε ~ N(0, 1), ρ = 0.9, started in its stationary distribution. The
  // exact variance of the mean of n samples (n ≫ correlation time) is
  //   σ_x²/n · (1+ρ)/(1−ρ),  σ_x² = 1/(1−ρ²),
  // 19× the naive σ_x²/n. Over 400 independent series of n = 20,000 the mean of the block
  // estimates must match the exact standard error within 5 % (the estimator's own spread with
  // 10 blocks is ≈ 24 % per series, 1.2 % over 400; blocks of 2,000 samples ≫ the correlation
  // time of 19 leave a bias of ≈ 2·19/2000 ≈ 2 %), and the naive estimate must be ≈ 4.4× smaller.
  const double rho = 0.9;
  const std::size_t n = 20000;
  const int series = 400;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> eps(0.0, 1.0);
  const double sigma_x = 1.0 / std::sqrt(1.0 - rho * rho);
  const double exact = sigma_x / std::sqrt(double(n)) * std::sqrt((1.0 + rho) / (1.0 - rho));
  double mean_estimate = 0.0, mean_naive = 0.0;
  for (int r = 0; r < series; ++r)
  {
    SampleSeries s;
    double x = sigma_x * eps(rng);
    for (std::size_t k = 0; k < n; ++k)
    {
      s.add(x);
      x = rho * x + eps(rng);
    }
    mean_estimate += s.standard_error() / series;
    double ss = 0.0;
    const double m = s.mean();
    for (double v : s.values())
      ss += (v - m) * (v - m);
    mean_naive += std::sqrt(ss / (n - 1) / n) / series;
  }
  EXPECT_NEAR(mean_estimate / exact, 1.0, 0.05);
  EXPECT_NEAR(exact / mean_naive, std::sqrt((1.0 + rho) / (1.0 - rho)), 0.15);
}
