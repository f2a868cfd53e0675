#include "common/study_repeats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace magbrush {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// The values of one key over the repeats that report it (NaN cells skipped).
struct Column
{
  std::vector<double> values, drifts, drift_errors;
  bool some_without_value = false; // a repeat reported the key as NaN (no verdict)
};

double mean(const std::vector<double> &v)
{
  if (v.empty())
    return nan;
  double s = 0.0;
  for (double x : v)
    s += x;
  return s / static_cast<double>(v.size());
}

// Standard error of the mean from the spread of independent samples.
double standard_error_of_mean(const std::vector<double> &v)
{
  const std::size_t n = v.size();
  if (n < 2)
    return nan;
  const double m = mean(v);
  double ss = 0.0;
  for (double x : v)
    ss += (x - m) * (x - m);
  return std::sqrt(ss / static_cast<double>(n - 1) / static_cast<double>(n));
}

// The verdict rows of dem/run_summary: combined, not averaged (see the header).
SummaryRow combined_verdict(const std::string &key, const Column &c)
{
  SummaryRow r{key, nan, nan};
  if (c.values.empty())
    return r;
  if (key == "steady_state")
    r.value = c.some_without_value ? nan : *std::min_element(c.values.begin(), c.values.end());
  else // significant_drift, drift_resolution
    r.value = *std::max_element(c.values.begin(), c.values.end());
  return r;
}
} // namespace

std::vector<SummaryRow> mean_of_repeats(const std::vector<std::vector<SummaryRow>> &repeats)
{
  std::vector<std::string> keys;
  std::vector<Column> columns;
  for (const auto &summary : repeats)
    for (const auto &row : summary)
    {
      auto it = std::find(keys.begin(), keys.end(), row.key);
      if (it == keys.end())
      {
        keys.push_back(row.key);
        columns.emplace_back();
        it = keys.end() - 1;
      }
      Column &c = columns[static_cast<std::size_t>(it - keys.begin())];
      if (std::isnan(row.value))
        c.some_without_value = true;
      else
        c.values.push_back(row.value);
      if (!std::isnan(row.drift))
      {
        c.drifts.push_back(row.drift);
        c.drift_errors.push_back(row.drift_standard_error);
      }
    }

  std::vector<SummaryRow> out;
  for (std::size_t k = 0; k < keys.size(); ++k)
  {
    const Column &c = columns[k];
    if (keys[k] == "steady_state" || keys[k] == "significant_drift" || keys[k] == "drift_resolution")
    {
      out.push_back(combined_verdict(keys[k], c));
      continue;
    }
    SummaryRow r{keys[k], mean(c.values), standard_error_of_mean(c.values)};
    if (!c.drifts.empty())
    {
      r.drift = mean(c.drifts);
      double sum_squares = 0.0;
      for (double e : c.drift_errors)
        sum_squares += e * e; // NaN when any repeat's drift had no error: then so has the mean
      r.drift_standard_error = std::sqrt(sum_squares) / static_cast<double>(c.drifts.size());
    }
    out.push_back(r);
  }
  return out;
}

} // namespace magbrush
