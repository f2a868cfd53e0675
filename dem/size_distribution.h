// The diameters of a population: a normal distribution of mean and standard deviation given
// in the case, truncated at ±3σ (and to no less than 5 % of the mean, so that a wide spread
// never draws a vanishing sphere). One rule for the places that make particles during a run —
// the inflow, the toner released from its carrier — so that the smallest size, which bounds
// the stable time step before such a particle exists, is known. (The insertion at the start
// keeps its positive-only truncation: dem/insertion.cpp says why.)
#pragma once

#include <algorithm>
#include <random>

namespace magbrush::dem {

class SizeDistribution
{
public:
  SizeDistribution() = default;
  SizeDistribution(double mean, double std)
      : mean_(mean), std_(std::max(0.0, std)), min_(std::max(0.05 * mean, mean - 3.0 * std_)),
        max_(mean + 3.0 * std_)
  {
  }

  double mean() const { return mean_; }
  double std() const { return std_; }
  double min() const { return min_; } // the smallest diameter drawn [m]
  double max() const { return max_; } // the largest [m]

  // One diameter: a draw outside [min, max] is redrawn.
  double draw(std::mt19937_64 &rng) const
  {
    if (std_ <= 0.0)
      return mean_;
    std::normal_distribution<double> normal(mean_, std_);
    for (;;)
    {
      const double d = normal(rng);
      if (d >= min_ && d <= max_)
        return d;
    }
  }

private:
  double mean_ = 0.0, std_ = 0.0, min_ = 0.0, max_ = 0.0;
};

} // namespace magbrush::dem
