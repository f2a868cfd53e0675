#include "common/study_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace magbrush {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> cells_of(const std::string &line)
{
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string c;
  while (std::getline(in, c, ','))
    out.push_back(c);
  return out;
}

double number_of(const std::string &text)
{
  if (text.empty() || text == "nan")
    return nan;
  char *end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() ? v : nan;
}

std::string format(double v)
{
  if (std::isnan(v))
    return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

const SummaryRow *find(const std::vector<SummaryRow> &rows, const std::string &key)
{
  for (const auto &r : rows)
    if (r.key == key)
      return &r;
  return nullptr;
}
} // namespace

std::vector<SummaryRow> read_summary_csv(const std::string &path)
{
  std::vector<SummaryRow> rows;
  std::ifstream in(path);
  std::string line;
  bool header = true;
  std::size_t drift = 0, drift_error = 0; // (0: no such column)
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    const auto c = cells_of(line);
    if (header)
    {
      header = false;
      for (std::size_t k = 1; k < c.size(); ++k)
      {
        drift = c[k] == "drift" ? k : drift;
        drift_error = c[k] == "drift_standard_error" ? k : drift_error;
      }
      continue;
    }
    if (c.size() < 2)
      continue;
    auto cell = [&c](std::size_t k) { return k > 0 && k < c.size() ? number_of(c[k]) : nan; };
    rows.push_back({c[0], number_of(c[1]), cell(2), cell(drift), cell(drift_error)});
  }
  return rows;
}

std::string study_table_csv(const std::string &comment, const std::vector<std::string> &leading_header,
                            const std::vector<std::string> &trailing_header, const std::vector<StudyPoint> &points,
                            const std::optional<MeasuredComparison> &comparison)
{
  // The columns: every key in the order first seen; a stderr column where any point has one,
  // and the drift with its standard error where any point tested the key for steady state.
  std::vector<std::string> keys;
  std::vector<char> has_error, has_drift;
  for (const auto &p : points)
    for (const auto &r : p.summary)
    {
      auto it = std::find(keys.begin(), keys.end(), r.key);
      if (it == keys.end())
      {
        keys.push_back(r.key);
        has_error.push_back(0);
        has_drift.push_back(0);
        it = keys.end() - 1;
      }
      const auto k = static_cast<std::size_t>(it - keys.begin());
      has_error[k] |= !std::isnan(r.standard_error);
      has_drift[k] |= !std::isnan(r.drift);
    }
  std::ostringstream o;
  if (!comment.empty())
    o << "# " << comment << "\n";
  o << "point";
  for (const auto &h : leading_header)
    o << "," << h;
  for (std::size_t k = 0; k < keys.size(); ++k)
    o << "," << keys[k] << (has_error[k] ? "," + keys[k] + "_stderr" : "")
      << (has_drift[k] ? "," + keys[k] + "_drift," + keys[k] + "_drift_stderr" : "");
  const int percent = comparison ? static_cast<int>(std::lround(100.0 * comparison->tolerance)) : 0;
  if (comparison)
    o << ",measured_" << comparison->key << ",relative_error_" << comparison->key << ",within_" << percent
      << "_percent_" << comparison->key;
  for (const auto &h : trailing_header)
    o << "," << h;
  o << "\n";
  for (std::size_t n = 0; n < points.size(); ++n)
  {
    const StudyPoint &p = points[n];
    o << p.label;
    for (const auto &c : p.leading)
      o << "," << c;
    for (std::size_t k = 0; k < keys.size(); ++k)
    {
      const SummaryRow *r = find(p.summary, keys[k]);
      o << "," << format(r ? r->value : nan);
      if (has_error[k])
        o << "," << format(r ? r->standard_error : nan);
      if (has_drift[k])
        o << "," << format(r ? r->drift : nan) << "," << format(r ? r->drift_standard_error : nan);
    }
    if (comparison)
    {
      const SummaryRow *r = find(p.summary, comparison->key);
      const double simulated = r ? r->value : nan;
      const double measured = n < comparison->measured.size() ? comparison->measured[n] : nan;
      const double error = (simulated - measured) / measured;
      o << "," << format(measured) << "," << format(error) << ","
        << (std::isnan(error) ? "nan" : std::abs(error) <= comparison->tolerance ? "1" : "0");
    }
    for (const auto &c : p.trailing)
      o << "," << c;
    o << "\n";
  }
  return o.str();
}

} // namespace magbrush
