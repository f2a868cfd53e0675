// The --quick preset of `magbrush run` (quick_preset.h).
#include "app/quick_preset.h"

#include <cstdio>

namespace magbrush {

namespace {
std::string ms(double seconds)
{
  char text[48];
  std::snprintf(text, sizeof text, "%.6g ms", seconds * 1e3);
  return text;
}
} // namespace

std::string QuickChange::override_text() const { return key + "=" + ms(to); }

std::vector<QuickChange> quick_preset(const Case &c)
{
  std::vector<QuickChange> changes;
  const double duration = c.dem.duration;
  if (!(duration > quick_duration))
    return changes;
  const double f = quick_duration / duration;
  const auto scale = [&](const std::string &key, double value) {
    if (value > 0.0)
      changes.push_back({key, value, value * f});
  };
  scale("dem.duration", duration);
  // Every key that places something in the run's time line (the averaging windows of the
  // measurements, case_validation.cpp check_averaging_windows, and the ramps at its start).
  scale("nip.average_from", c.nip.average_from);
  scale("development.average_from", c.development.average_from);
  scale("dma.average_from", c.dma.average_from);
  scale("flow_report.average_from", c.flow.average_from);
  if (c.sleeve)
    scale("sleeve.spin_up_time", c.sleeve->spin_up_time);
  if (c.drum.present)
    scale("drum.spin_up_time", c.drum.spin_up_time);
  scale("applied_field.ramp_time", c.applied_field.ramp_time);
  return changes;
}

std::string describe(const std::vector<QuickChange> &changes)
{
  std::string text;
  char line[160];
  for (const auto &q : changes)
  {
    std::snprintf(line, sizeof line, "  %-26s %s -> %s\n", q.key.c_str(), ms(q.from).c_str(), ms(q.to).c_str());
    text += line;
  }
  return text;
}

std::string quick_caveats(const Case &c, const std::vector<QuickChange> &changes)
{
  if (changes.empty())
    return "";
  const double end = changes.front().to; // dem.duration comes first
  std::string text;
  for (const auto &p : c.planes)
    if (!p.path.empty() && p.path.back().first > end)
      text += "  note: the path of wall '" + p.name + "' runs to " + ms(p.path.back().first) +
              " and is not scaled: the quick run stops part-way through it\n";
  return text;
}

} // namespace magbrush
