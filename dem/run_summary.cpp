#include "dem/run_summary.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

namespace magbrush::dem {

namespace {
// A CSV cell without the separator (the meanings are prose).
std::string cell(std::string text)
{
  std::replace(text.begin(), text.end(), ',', ';');
  return text;
}

std::string number(double v)
{
  if (std::isnan(v))
    return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
} // namespace

std::string run_summary_csv(const std::vector<std::unique_ptr<Measurement>> &measurements,
                            const StatisticsSettings &statistics)
{
  std::ostringstream o;
  o << "# magbrush run summary: every measurement's key numbers; standard errors by block averaging over "
    << statistics.blocks << " blocks; drift = (mean of 2nd half - mean of 1st half) / |mean| (negative: falling), with its own "
    << "standard error from each half's blocks\n";
  o << "key,value,standard_error,drift,unit,meaning,measurement,drift_standard_error\n";
  SteadyStateVerdict verdict;
  for (const auto &m : measurements)
    for (const SummaryValue &v : m->summary())
    {
      o << cell(v.key) << "," << number(v.value) << "," << number(v.standard_error) << "," << number(v.drift) << ","
        << cell(v.unit) << "," << cell(v.meaning) << "," << cell(m->name()) << "," << number(v.drift_standard_error)
        << "\n";
      verdict.add(v, statistics.steady_drift);
    }
  o << verdict.rows(statistics.steady_drift);
  return o.str();
}

void SteadyStateVerdict::add(const SummaryValue &v, double tolerance)
{
  if (std::isnan(v.drift))
    return;
  ++tested;
  steady += std::abs(v.drift) < tolerance;
  if (std::isnan(v.drift_standard_error))
    return;
  ++with_error;
  trending += std::abs(v.drift) > 2.0 * v.drift_standard_error;
  resolution = std::max(resolution, 2.0 * v.drift_standard_error);
}

std::string SteadyStateVerdict::rows(double tolerance) const
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto row = [](const char *key, double value, const std::string &meaning) {
    return std::string(key) + "," + number(value) + ",nan,nan,1," + cell(meaning) + ",run,nan\n";
  };
  char text[256];
  std::snprintf(text, sizeof text, "%d of %d tested means drift < %.3g %% between the halves of their window", steady,
                tested, 100.0 * tolerance);
  std::string out = row("steady_state", tested == 0 ? nan : steady == tested ? 1.0 : 0.0, text);
  std::snprintf(text, sizeof text,
                "%d of %d tested means drift by more than two of the drift's standard errors (a trend; the rest is "
                "noise)",
                trending, with_error);
  out += row("significant_drift", with_error == 0 ? nan : trending > 0 ? 1.0 : 0.0, text);
  std::snprintf(text, sizeof text,
                "two standard errors of the drift of the noisiest tested mean: the smallest drift this window tells "
                "from noise (above %.3g the steady-state test needs more samples)",
                tolerance);
  out += row("drift_resolution", with_error == 0 ? nan : resolution, text);
  return out;
}
void write_run_summary(const std::string &directory, const std::vector<std::unique_ptr<Measurement>> &measurements,
                       const StatisticsSettings &statistics)
{
  write_text_atomically((std::filesystem::path(directory) / "summary.csv").string(),
                        run_summary_csv(measurements, statistics));
}

} // namespace magbrush::dem
