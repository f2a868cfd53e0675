// One row of the stress suite's table (tools/stress, docs/stress.md): what a case did.
// Every row is printed ("stress| ..."); when MAGBRUSH_STRESS_TABLE names a file the row is
// also appended to it as CSV (case, setting, outcome, figure, message, seconds), which
// tools/stress collects. The seconds are information for the table, never asserted.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace magbrush::dem::testing {

// What a case did: the right answer, a stop with a message, or a refusal before the run.
enum class StressOutcome
{
  right,   // gave the answer the case checks (the figure says how close)
  stopped, // a stability guard stopped the run with a message naming the cause
  refused  // the set-up refused the input with a message (e.g. a step above the limit)
};

inline const char *outcome_name(StressOutcome o)
{
  switch (o)
  {
  case StressOutcome::right: return "right answer";
  case StressOutcome::stopped: return "stopped with message";
  case StressOutcome::refused: return "refused at set-up";
  }
  return "?";
}

struct StressRow
{
  std::string case_name, setting;
  StressOutcome outcome = StressOutcome::right;
  std::string figure;  // the measured figure (error against the exact answer, ...)
  std::string message; // the guard's or the set-up's message ("" for a right answer)
  double seconds = 0.0;
};

inline std::string csv_field(const std::string &s)
{
  std::string out = "\"";
  for (char ch : s)
    out += ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch);
  return out + "\"";
}

inline void record_stress_row(const StressRow &r)
{
  std::printf("stress| %s | %s | %s | %s | %.2f s | %s\n", r.case_name.c_str(), r.setting.c_str(),
              outcome_name(r.outcome), r.figure.c_str(), r.seconds, r.message.c_str());
  std::fflush(stdout);
  if (const char *path = std::getenv("MAGBRUSH_STRESS_TABLE"))
  {
    std::ofstream out(path, std::ios::app);
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.2f", r.seconds);
    out << csv_field(r.case_name) << "," << csv_field(r.setting) << "," << csv_field(outcome_name(r.outcome)) << ","
        << csv_field(r.figure) << "," << csv_field(r.message) << "," << seconds << "\n";
  }
}

} // namespace magbrush::dem::testing
