// The diameters of a population: a normal distribution truncated at ±3σ, one rule for the
// inflow and the toner released from its carrier (dem/size_distribution.h).
#include "dem/size_distribution.h"

#include <gtest/gtest.h>

#include <cmath>

using magbrush::dem::SizeDistribution;

namespace {
// The standard deviation of a normal truncated at ±c σ, over σ (exact):
// sqrt(1 - 2 c φ(c) / (2 Φ(c) - 1)).
double truncated_std_factor(double c)
{
  const double phi = std::exp(-0.5 * c * c) / std::sqrt(2.0 * M_PI);
  const double mass = std::erf(c / std::sqrt(2.0));
  return std::sqrt(1.0 - 2.0 * c * phi / mass);
}
} // namespace

TEST(SizeDistribution, DrawsANormalTruncatedAtThreeSigma)
{
  const SizeDistribution size(35e-6, 3.5e-6);
  EXPECT_DOUBLE_EQ(size.min(), 35e-6 - 10.5e-6);
  EXPECT_DOUBLE_EQ(size.max(), 35e-6 + 10.5e-6);
  std::mt19937_64 rng(7);
  const int n = 400000;
  double sum = 0.0, sum2 = 0.0, lo = 1.0, hi = 0.0;
  for (int k = 0; k < n; ++k)
  {
    const double d = size.draw(rng);
    sum += d;
    sum2 += d * d;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_GE(lo, size.min());
  EXPECT_LE(hi, size.max());
  // 400,000 draws: the mean to 5 standard errors, the spread (0.9866 σ) to 0.5 %; an
  // untruncated normal has σ, 1.4 % more.
  EXPECT_NEAR(mean, 35e-6, 5.0 * 3.5e-6 / std::sqrt(n));
  EXPECT_NEAR(sd / 3.5e-6, truncated_std_factor(3.0), 0.005);
}

TEST(SizeDistribution, AWideSpreadNeverDrawsLessThanAVanishingSphere)
{
  const SizeDistribution size(10e-6, 8e-6); // mean - 3σ < 0
  EXPECT_DOUBLE_EQ(size.min(), 0.5e-6);     // 5 % of the mean
  std::mt19937_64 rng(1);
  for (int k = 0; k < 10000; ++k)
    EXPECT_GE(size.draw(rng), 0.5e-6);
  const SizeDistribution fixed(10e-6, 0.0);
  EXPECT_EQ(fixed.draw(rng), 10e-6);
}
