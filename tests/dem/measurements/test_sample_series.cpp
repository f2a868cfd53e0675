// Block-averaged standard errors and the steady-state drift (dem/measurements/sample_series.h)
// against exact results: the drift of a linear ramp, and the standard error of the mean of a
// correlated AR(1) series, whose exact value the naive σ/√n misses by a factor 4.4.
#include "dem/measurements/sample_series.h"
#include "dem/run_summary.h"

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

  // The same ramp downwards: the same size, the sign says it falls.
  SampleSeries falling;
  for (int k = 0; k < n; ++k)
    falling.add(1.0 + a - a * k / n);
  EXPECT_NEAR(falling.drift(), -(a / 2.0) / (1.0 + a - a * (n - 1) / (2.0 * n)), 1e-13);
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

TEST(SampleSeries, DriftStandardErrorOfWhiteNoiseMatchesTheExactValue)
{
  // Independent samples N(μ, σ²), n of them: each half's mean has the variance σ²/(n/2), so the
  // drift |m₂ − m₁|/μ has the exact standard error 2σ/(√n μ). Over 400 series the block estimate
  // (5 blocks per half) must match it within 6 % (its spread per series is ≈ 25 %, 1.3 % over
  // 400; the square root of an unbiased variance with 8 degrees of freedom is ≈ 3 % low), and a
  // drift beyond two of them must be as rare as chance makes it (≈ 8 % for a t with 8 degrees
  // of freedom).
  const double mu = 10.0, sigma = 1.0;
  const std::size_t n = 2000;
  const int series = 400;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> sample(mu, sigma);
  const double exact = 2.0 * sigma / (std::sqrt(double(n)) * mu);
  double mean_estimate = 0.0;
  int beyond_two = 0;
  for (int r = 0; r < series; ++r)
  {
    SampleSeries s;
    for (std::size_t k = 0; k < n; ++k)
      s.add(sample(rng));
    const double se = s.drift_standard_error();
    mean_estimate += se / series;
    beyond_two += std::abs(s.drift()) > 2.0 * se;
  }
  EXPECT_NEAR(mean_estimate / exact, 1.0, 0.06);
  EXPECT_GT(beyond_two, series * 3 / 100);
  EXPECT_LT(beyond_two, series * 14 / 100);
}

TEST(SampleSeries, ATrendStandsOutOfItsNoiseAndNoiseDoesNot)
{
  // A 10 % ramp under noise of 1 %: the halves differ by 5 %. The ramp also rises within each
  // half (by 1 % per block of 100 samples), and that rise enters the half's block spread, so the
  // drift's error is the ramp's own order, ≈ √2 × sd(0, 1, 2, 3, 4 %)/√5 ≈ 1 %: conservative —
  // a trend is called only beyond what the halves' own spread allows — and still ≈ 5 standard
  // errors here. The same noise without the ramp drifts within two standard errors, whose size
  // is the noise's: 2 × 0.01 / √1000 exactly, the estimate within a factor 2.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  SampleSeries ramp, flat;
  const int n = 1000;
  for (int k = 0; k < n; ++k)
  {
    const double e = noise(rng);
    ramp.add(1.0 + 0.1 * k / n + e);
    flat.add(1.0 + e);
  }
  EXPECT_GT(ramp.drift(), 4.0 * ramp.drift_standard_error());
  EXPECT_NEAR(ramp.drift_standard_error(), std::sqrt(2.0 * 2.5e-4 / 5.0) / ramp.mean(), 0.3e-2);
  EXPECT_LT(flat.drift(), 2.0 * flat.drift_standard_error());
  const double noise_only = 2.0 * 0.01 / std::sqrt(double(n));
  EXPECT_GT(flat.drift_standard_error(), 0.5 * noise_only);
  EXPECT_LT(flat.drift_standard_error(), 2.0 * noise_only);
  SampleSeries few;
  for (int k = 0; k < 18; ++k)
    few.add(k + 1.0);
  EXPECT_TRUE(std::isnan(few.drift_standard_error())); // 5 blocks of 2 per half need 20 samples
  EXPECT_FALSE(std::isnan(few.drift_standard_error(4)));
}

// A ratio of sums: blocks whose ratios are known exactly give the standard error of their mean.
TEST(SampleSeries, RatioStandardErrorIsTheScatterOfTheBlocksRatios)
{
  SampleSeries num, den;
  // 4 blocks of 3 samples; block k has den = 2, 4, 6 (sum 12) and num = r_k × den.
  const double r[4] = {0.30, 0.34, 0.36, 0.40};
  for (int k = 0; k < 4; ++k)
    for (double d : {2.0, 4.0, 6.0})
    {
      den.add(d);
      num.add(r[k] * d);
    }
  // Mean 0.35, deviations -0.05, -0.01, 0.01, 0.05: s^2 = 0.0052/3, SE^2 = s^2/4.
  EXPECT_NEAR(ratio_standard_error(num, den, 4), std::sqrt(0.0052 / 3.0 / 4.0), 1e-14);
  // One constant ratio: no scatter.
  SampleSeries twice;
  for (double v : den.values())
    twice.add(2.0 * v);
  EXPECT_NEAR(ratio_standard_error(twice, den, 4), 0.0, 1e-15);
  // Too few samples per block, or series of different lengths: no number.
  EXPECT_TRUE(std::isnan(ratio_standard_error(num, den, 8)));
  twice.add(1.0);
  EXPECT_TRUE(std::isnan(ratio_standard_error(twice, den, 4)));
}

TEST(SteadyStateVerdict, SaysWhetherAFailedTestIsATrendOrTooLittleData)
{
  using magbrush::dem::SteadyStateVerdict;
  using magbrush::dem::SummaryValue;
  auto tested = [](double drift, double error) {
    SummaryValue v;
    v.key = "x", v.value = 1.0, v.drift = drift, v.drift_standard_error = error;
    return v;
  };
  SteadyStateVerdict trend;
  trend.add(tested(0.05, 0.01), 0.02); // 5 standard errors: a trend
  trend.add(tested(0.01, 0.004), 0.02);
  const std::string t = trend.rows(0.02);
  EXPECT_NE(t.find("steady_state,0,"), std::string::npos) << t;
  EXPECT_NE(t.find("significant_drift,1,"), std::string::npos) << t;
  EXPECT_NE(t.find("drift_resolution,0.02,"), std::string::npos) << t;

  SteadyStateVerdict noisy;
  noisy.add(tested(0.05, 0.04), 0.02); // 1.25 standard errors: noise, and a window that cannot resolve 2 %
  noisy.add(tested(0.01, std::nan("")), 0.02);
  const std::string n = noisy.rows(0.02);
  EXPECT_NE(n.find("steady_state,0,"), std::string::npos) << n;
  EXPECT_NE(n.find("significant_drift,0,"), std::string::npos) << n;
  EXPECT_NE(n.find("drift_resolution,0.08,"), std::string::npos) << n;
  EXPECT_NE(n.find("0 of 1 tested means drift by more"), std::string::npos) << n;

  SteadyStateVerdict none;
  EXPECT_NE(none.rows(0.02).find("steady_state,nan,"), std::string::npos);
  EXPECT_NE(none.rows(0.02).find("significant_drift,nan,"), std::string::npos);
}
