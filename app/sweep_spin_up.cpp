// One spin-up for every point of a sweep (see sweep_spin_up.h).
#include "app/sweep_spin_up.h"

#include "common/atomic_file.h"
#include "common/command_line.h"
#include "case/case_hash.h"
#include "case/units.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace magbrush {

namespace fs = std::filesystem;

namespace {

constexpr const char *record_name = "spin_up.csv";

std::string seconds_text(double s)
{
  char text[64];
  std::snprintf(text, sizeof text, "%.9gs", s);
  return text;
}

std::string ms(double s)
{
  char text[64];
  std::snprintf(text, sizeof text, "%.3g ms", s * 1e3);
  return text;
}

double time_option(const std::string &option, const std::string &text)
{
  try
  {
    return parse_quantity(text, Dimension::time);
  }
  catch (const std::exception &e)
  {
    throw cli::UsageError(option + " expects a time with its unit (e.g. 8ms), found '" + text + "': " + e.what());
  }
}

} // namespace

std::optional<SweepSpinUp> plan_spin_up(const std::string &spin_up_text, const std::string &settle_text,
                                        const Case &base, const fs::path &sweep_dir)
{
  if (spin_up_text.empty())
  {
    if (!settle_text.empty())
      throw cli::UsageError("--settle is the points' transient after a spin-up: give --spin-up too");
    return std::nullopt;
  }
  if (settle_text.empty())
    throw cli::UsageError("--spin-up needs --settle: how long after the fork the points' averages start.\n" +
                          settle_estimate(base));
  SweepSpinUp s;
  s.duration = time_option("--spin-up", spin_up_text);
  s.settle = time_option("--settle", settle_text);
  if (!(s.duration > 0.0) || s.settle < 0.0)
    throw cli::UsageError("--spin-up must be positive and --settle not negative");
  if (!(s.averages_from() < base.dem.duration))
    throw cli::UsageError("the spin-up (" + ms(s.duration) + ") and the settle (" + ms(s.settle) +
                          ") leave nothing to average before dem.duration (" + ms(base.dem.duration) + ")");
  s.dir = sweep_dir / "spin_up";
  Case spin_case = base;
  spin_case.dem.duration = s.duration;
  s.case_digest = case_hash(spin_case);
  return s;
}

std::string settle_estimate(const Case &c)
{
  if (!c.sleeve || !c.drum.present)
    return "  (the case has no sleeve and drum to estimate the settle from)\n";
  std::ostringstream o;
  const double v_sleeve = std::abs(c.sleeve->omega()) * c.sleeve->radius;
  const double v_drum = std::abs(c.drum.omega()) * c.drum.radius;
  if (c.flow.outflow() && c.flow.inflow() && v_sleeve > 0.0)
  {
    const double arc = std::abs(std::remainder(c.flow.outflow_angle - c.flow.inflow_angle, 2.0 * M_PI));
    o << "  the spin-up's carriers ride from the feed to the outflow (" << arc * 180.0 / M_PI << " deg) in "
      << ms(arc * c.sleeve->radius / v_sleeve) << " at the sleeve's speed (longer where they wait in a bank)\n";
    if (v_drum > 0.0)
    {
      const double x_feed = c.sleeve->radius * std::remainder(c.flow.inflow_angle - c.drum.angle, 2.0 * M_PI);
      o << "  a drum element takes " << ms((c.development.measure_to - x_feed) / v_drum) << " from the feed (x = "
        << x_feed * 1e3 << " mm along the nip) to the measuring line (development.measure_to = "
        << c.development.measure_to * 1e3 << " mm) at the drum's speed\n";
    }
  }
  else if (v_drum > 0.0)
    o << "  a drum element takes " << ms(c.development.measure_to / v_drum)
      << " from the gap centre to the measuring line at the drum's speed\n";
  return o.str().empty() ? "  (the case has no moving sleeve or drum to estimate it from)\n"
                         : "What the speeds say (the settle covers the history of the fork leaving the measured "
                           "region):\n" + o.str();
}

bool spin_up_done(const SweepSpinUp &s)
{
  std::ifstream in(s.dir / record_name);
  std::string line, header;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    if (header.empty())
    {
      header = line;
      continue;
    }
    // case_digest,duration_s,run_time_s
    return line.rfind(s.case_digest + ",", 0) == 0 && fs::exists(s.checkpoint());
  }
  return false;
}

void record_spin_up(const SweepSpinUp &s, double run_time_s)
{
  char cells[128];
  std::snprintf(cells, sizeof cells, ",%.9g,%.1f\n", s.duration, run_time_s);
  write_text_atomically((s.dir / record_name).string(),
                        "# magbrush sweep: the spin-up every point of this sweep was forked from\n"
                        "case_digest,duration_s,run_time_s\n" +
                            s.case_digest + cells);
}

std::vector<std::string> fork_words(const SweepSpinUp &s, const Case &c)
{
  std::vector<std::string> words = {"--restart", s.checkpoint().string(), "--restart-anyway"};
  const double from = s.averages_from();
  const auto later = [&](const char *key, double value) {
    if (value < from)
    {
      words.push_back("--set");
      words.push_back(std::string(key) + "=" + seconds_text(from));
    }
  };
  later("development.average_from", c.development.average_from);
  later("nip.average_from", c.nip.average_from);
  later("dma.average_from", c.dma.average_from);
  later("flow_report.average_from", c.flow.average_from);
  return words;
}

std::string spin_up_header_cells() { return ",spin_up,spin_up_end_s,spin_up_case_digest,averages_from_s"; }

std::string spin_up_cells(const std::optional<SweepSpinUp> &s)
{
  if (!s)
    return ",,,,";
  char cells[256];
  std::snprintf(cells, sizeof cells, ",%s,%.9g,%s,%.9g", s->dir.string().c_str(), s->duration,
                s->case_digest.c_str(), s->averages_from());
  return cells;
}

} // namespace magbrush
