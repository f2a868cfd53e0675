#include "dem/run_summary.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
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
    << statistics.blocks << " blocks; drift = |mean of 2nd half - mean of 1st half| / |mean|\n";
  o << "key,value,standard_error,drift,unit,meaning,measurement\n";
  int tested = 0, steady = 0;
  for (const auto &m : measurements)
    for (const SummaryValue &v : m->summary())
    {
      o << cell(v.key) << "," << number(v.value) << "," << number(v.standard_error) << "," << number(v.drift) << ","
        << cell(v.unit) << "," << cell(v.meaning) << "," << cell(m->name()) << "\n";
      if (!std::isnan(v.drift))
      {
        ++tested;
        steady += v.drift < statistics.steady_drift;
      }
    }
  char meaning[128];
  std::snprintf(meaning, sizeof meaning, "%d of %d tested means drift < %.3g %% between the halves of their window",
                steady, tested, 100.0 * statistics.steady_drift);
  o << "steady_state," << (tested == 0 ? "nan" : steady == tested ? "1" : "0") << ",nan,nan,1," << meaning << ",run\n";
  return o.str();
}

void write_run_summary(const std::string &directory, const std::vector<std::unique_ptr<Measurement>> &measurements,
                       const StatisticsSettings &statistics)
{
  write_text_atomically((std::filesystem::path(directory) / "summary.csv").string(),
                        run_summary_csv(measurements, statistics));
}

} // namespace magbrush::dem
