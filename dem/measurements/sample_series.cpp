#include "dem/measurements/sample_series.h"

#include <cmath>
#include <limits>
#include <numeric>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

double mean_of(std::vector<double>::const_iterator first, std::vector<double>::const_iterator last)
{
  const auto n = std::distance(first, last);
  return n > 0 ? std::accumulate(first, last, 0.0) / static_cast<double>(n) : nan;
}
} // namespace

double SampleSeries::mean() const { return mean_of(values_.begin(), values_.end()); }

double SampleSeries::standard_error(std::size_t blocks) const
{
  if (blocks < 2)
    return nan;
  const std::size_t length = values_.size() / blocks;
  if (length < 2)
    return nan;
  // The newest blocks × length samples: the oldest ones are nearest the transient.
  const auto start = values_.end() - static_cast<std::ptrdiff_t>(blocks * length);
  std::vector<double> block_means(blocks);
  for (std::size_t b = 0; b < blocks; ++b)
  {
    const auto first = start + static_cast<std::ptrdiff_t>(b * length);
    block_means[b] = mean_of(first, first + static_cast<std::ptrdiff_t>(length));
  }
  const double m = mean_of(block_means.begin(), block_means.end());
  double ss = 0.0;
  for (double v : block_means)
    ss += (v - m) * (v - m);
  const double variance_of_block_means = ss / static_cast<double>(blocks - 1);
  return std::sqrt(variance_of_block_means / static_cast<double>(blocks));
}

double SampleSeries::drift() const
{
  if (values_.size() < 4)
    return nan;
  const auto middle = values_.begin() + static_cast<std::ptrdiff_t>(values_.size() / 2);
  const double first = mean_of(values_.begin(), middle), second = mean_of(middle, values_.end());
  const double m = mean();
  return m != 0.0 ? std::abs(second - first) / std::abs(m) : nan;
}

} // namespace magbrush::dem
