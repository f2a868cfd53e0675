// The table of a study (`magbrush sweep`): one row per point of the sweep, and as columns the
// varied values followed by every key number the runs' measurements reported (each run's
// dem/summary.csv, dem/run_summary.h), with the standard error next to each mean that has one,
// and — when a measured series is given — the measured value, the relative error and whether
// it is within the tolerance (Kweon's criterion: 10 %).
//
// The table knows no physics: the measurements decide what they report, so a new measurement
// appears in every study without touching the sweep.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace magbrush {

struct SummaryRow
{
  std::string key;
  double value;
  double standard_error; // NaN: none
  // The steady-state test's numbers for this key, where the run tested it: the relative drift
  // between the halves of the averaging window and the drift's own standard error.
  double drift = std::numeric_limits<double>::quiet_NaN();
  double drift_standard_error = std::numeric_limits<double>::quiet_NaN();
};

// The rows of a run's summary.csv (key,value,standard_error,... with the columns drift and
// drift_standard_error found by name); an absent or unreadable file gives no rows.
std::vector<SummaryRow> read_summary_csv(const std::string &path);

struct StudyPoint
{
  std::string label;
  std::vector<std::string> leading;  // cells before the summary columns (the varied values, ...)
  std::vector<SummaryRow> summary;   // the run's key numbers
  std::vector<std::string> trailing; // cells after them (run time, status)
};

struct MeasuredComparison
{
  std::string key;              // the summary column compared (e.g. tma_kg_per_m2)
  std::vector<double> measured; // one per point, NaN where the measured file has no value
  double tolerance = 0.10;      // relative
};

// The table as CSV: "point", the leading header, every summary key in the order first seen
// (with "<key>_stderr" after it when any point has a standard error for it, then "<key>_drift"
// and "<key>_drift_stderr" when any point tested it for steady state), then for a
// comparison "measured_<key>", "relative_error_<key>", "within_<p>_percent_<key>", then the
// trailing header. A point without a key gets "nan".
std::string study_table_csv(const std::string &comment, const std::vector<std::string> &leading_header,
                            const std::vector<std::string> &trailing_header, const std::vector<StudyPoint> &points,
                            const std::optional<MeasuredComparison> &comparison = std::nullopt);

} // namespace magbrush
