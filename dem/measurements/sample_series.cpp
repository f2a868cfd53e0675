#include "dem/measurements/sample_series.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

using Iterator = std::vector<double>::const_iterator;

double mean_of(Iterator first, Iterator last)
{
  const auto n = std::distance(first, last);
  return n > 0 ? std::accumulate(first, last, 0.0) / static_cast<double>(n) : nan;
}

// The block means of the newest blocks × length samples of [first, last), length = n / blocks.
// Empty when a block would hold fewer than two samples.
std::vector<double> block_means(Iterator first, Iterator last, std::size_t blocks)
{
  const auto n = static_cast<std::size_t>(std::distance(first, last));
  const std::size_t length = blocks > 0 ? n / blocks : 0;
  if (length < 2)
    return {};
  // The newest blocks × length samples: the oldest ones are nearest the transient.
  const auto start = last - static_cast<std::ptrdiff_t>(blocks * length);
  std::vector<double> means(blocks);
  for (std::size_t b = 0; b < blocks; ++b)
  {
    const auto from = start + static_cast<std::ptrdiff_t>(b * length);
    means[b] = mean_of(from, from + static_cast<std::ptrdiff_t>(length));
  }
  return means;
}

// The squared standard error of the mean of nearly independent block means.
double squared_error_of_mean(const std::vector<double> &means)
{
  const double m = mean_of(means.begin(), means.end());
  double ss = 0.0;
  for (double v : means)
    ss += (v - m) * (v - m);
  const auto b = static_cast<double>(means.size());
  return ss / (b - 1.0) / b;
}
} // namespace

double SampleSeries::mean() const { return mean_of(values_.begin(), values_.end()); }

double SampleSeries::standard_error(std::size_t blocks) const
{
  if (blocks < 2)
    return nan;
  const std::vector<double> means = block_means(values_.begin(), values_.end(), blocks);
  return means.empty() ? nan : std::sqrt(squared_error_of_mean(means));
}

double SampleSeries::drift() const
{
  if (values_.size() < 4)
    return nan;
  const auto middle = values_.begin() + static_cast<std::ptrdiff_t>(values_.size() / 2);
  const double first = mean_of(values_.begin(), middle), second = mean_of(middle, values_.end());
  const double m = mean();
  return m != 0.0 ? (second - first) / std::abs(m) : nan;
}

double SampleSeries::drift_standard_error(std::size_t blocks) const
{
  const std::size_t per_half = blocks / 2;
  if (per_half < 2)
    return nan;
  const auto middle = values_.begin() + static_cast<std::ptrdiff_t>(values_.size() / 2);
  const std::vector<double> first = block_means(values_.begin(), middle, per_half);
  const std::vector<double> second = block_means(middle, values_.end(), per_half);
  const double m = mean();
  if (first.empty() || second.empty() || m == 0.0)
    return nan;
  return std::sqrt(squared_error_of_mean(first) + squared_error_of_mean(second)) / std::abs(m);
}

SummaryValue summarise(const SampleSeries &series, std::size_t blocks, bool steady_test, std::string key,
                       std::string unit, std::string meaning)
{
  SummaryValue v;
  v.key = std::move(key);
  v.value = series.mean();
  v.standard_error = series.standard_error(blocks);
  if (steady_test)
  {
    v.drift = series.drift();
    v.drift_standard_error = series.drift_standard_error(blocks);
  }
  v.unit = std::move(unit);
  v.meaning = std::move(meaning);
  return v;
}

double ratio_standard_error(const SampleSeries &num, const SampleSeries &den, std::size_t blocks)
{
  const std::vector<double> &a = num.values(), &b = den.values();
  if (blocks < 2 || a.size() != b.size())
    return nan;
  // Equal-length blocks have sums proportional to their means: the ratio of means is theirs.
  const std::vector<double> top = block_means(a.begin(), a.end(), blocks);
  const std::vector<double> bottom = block_means(b.begin(), b.end(), blocks);
  if (top.empty())
    return nan;
  std::vector<double> ratios(top.size());
  for (std::size_t k = 0; k < top.size(); ++k)
  {
    if (bottom[k] == 0.0)
      return nan;
    ratios[k] = top[k] / bottom[k];
  }
  return std::sqrt(squared_error_of_mean(ratios));
}

SummaryValue summarise_blocks(const std::vector<double> &blocks, bool steady_test, std::string key,
                              std::string unit, std::string meaning)
{
  SummaryValue v;
  v.key = std::move(key);
  v.unit = std::move(unit);
  v.meaning = std::move(meaning);
  const std::size_t n = blocks.size();
  v.value = mean_of(blocks.begin(), blocks.end());
  if (n >= 2)
    v.standard_error = std::sqrt(squared_error_of_mean(blocks));
  if (steady_test && n >= 2 && v.value != 0.0)
  {
    const std::vector<double> older(blocks.begin(), blocks.begin() + static_cast<std::ptrdiff_t>(n / 2));
    const std::vector<double> newer(blocks.begin() + static_cast<std::ptrdiff_t>(n / 2), blocks.end());
    v.drift = (mean_of(newer.begin(), newer.end()) - mean_of(older.begin(), older.end())) / std::abs(v.value);
    if (older.size() >= 2 && newer.size() >= 2)
      v.drift_standard_error =
        std::sqrt(squared_error_of_mean(older) + squared_error_of_mean(newer)) / std::abs(v.value);
  }
  return v;
}

} // namespace magbrush::dem
