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
  o << "key,value,standard_error,drift,unit,meaning,measurement,drift_standard_error,state\n";
  SteadyStateVerdict verdict;
  for (const auto &m : measurements)
    for (const SummaryValue &v : m->summary())
    {
      o << cell(v.key) << "," << number(v.value) << "," << number(v.standard_error) << "," << number(v.drift) << ","
        << cell(v.unit) << "," << cell(v.meaning) << "," << cell(m->name()) << "," << number(v.drift_standard_error)
        << "," << (v.state ? 1 : 0) << "\n";
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
  const bool within = std::abs(v.drift) < tolerance;
  steady += within;
  const bool has_error = !std::isnan(v.drift_standard_error);
  const bool beyond_noise = has_error && std::abs(v.drift) > 2.0 * v.drift_standard_error;
  if (v.state)
  {
    // A state value's noise is small (hundreds of beads counted, not their forces): a drift
    // below the tolerance is steady even when it is resolved; one above it and beyond its
    // noise is a transient (a trend).
    ++states;
    steady_states += within;
    trending += !within && beyond_noise;
    return;
  }
  // Beyond the tolerance and beyond its noise, or beyond the tolerance with no error to tell it
  // from noise (too few samples for blocks): either way not shown steady.
  observables_beyond += !within && (beyond_noise || !has_error);
  if (!has_error)
    return;
  ++with_error;
  trending += beyond_noise;
  resolution = std::max(resolution, 2.0 * v.drift_standard_error);
}

double SteadyStateVerdict::verdict() const
{
  if (tested == 0)
    return std::numeric_limits<double>::quiet_NaN();
  if (states == 0)
    return steady == tested ? 1.0 : 0.0;
  return steady_states == states && observables_beyond == 0 ? 1.0 : 0.0;
}

std::string SteadyStateVerdict::rows(double tolerance) const
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto row = [](const char *key, double value, const std::string &meaning) {
    return std::string(key) + "," + number(value) + ",nan,nan,1," + cell(meaning) + ",run,nan,0\n";
  };
  char text[320];
  if (states == 0)
    std::snprintf(text, sizeof text, "%d of %d tested means drift < %.3g %% between the halves of their window",
                  steady, tested, 100.0 * tolerance);
  else
    std::snprintf(text, sizeof text,
                  "%d of %d state values (beads held) drift < %.3g %% between the halves of their window; %d of %d "
                  "other tested means drift beyond both that and two standard errors",
                  steady_states, states, 100.0 * tolerance, observables_beyond, tested - states);
  std::string out = row("steady_state", verdict(), text);
  std::snprintf(text, sizeof text,
                "%d of %d tested means drift by more than two of the drift's standard errors (a trend; the rest is "
                "noise)",
                trending, with_error + states);
  out += row("significant_drift", with_error + states == 0 ? nan : trending > 0 ? 1.0 : 0.0, text);
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
