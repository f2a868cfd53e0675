#include "dem/restart_check.h"

#include "case/case_hash.h"

#include <map>

namespace magbrush::dem {

bool is_run_control_key(const std::string &key)
{
  static const char *const exact[] = {"dem.duration", "dem.leg", "dem.output_interval", "dem.checkpoint_interval",
                                      "dem.checkpoint_wall_interval", "dem.threads",
                                      // where the stored fields are: what they hold is checked
                                      // against the case when they are read (their provenance)
                                      "field.output_dir"};
  for (const char *k : exact)
    if (key == k)
      return true;
  // Where to write, and whole sections that only say what to measure and how to judge it:
  // sampling does not change the particles' bits, so a continued run may average over a new
  // window (--set dma.average_from=30ms) without --restart-anyway; its measurements then start
  // afresh at the restart (is_measurement_key).
  return key.rfind("output.", 0) == 0 || is_measurement_key(key);
}

bool is_measurement_key(const std::string &key)
{
  if (key == "compression.sample_interval" || key == "compression.map_interval")
    return true;
  static const char *const sections[] = {"nip.", "dma.", "development.", "flow_report.", "statistics."};
  for (const char *prefix : sections)
    if (key.rfind(prefix, 0) == 0)
      return true;
  return false;
}

std::vector<CaseDifference> case_differences(const CheckpointIdentity &checkpoint, const CheckpointIdentity &now)
{
  std::map<std::string, std::string> current(now.inputs.begin(), now.inputs.end());
  std::map<std::string, bool> seen;
  std::vector<CaseDifference> out;
  auto add = [&out](const std::string &key, const std::string &a, const std::string &b) {
    out.push_back({key, a, b, is_run_control_key(key)});
  };
  for (const auto &[key, value] : checkpoint.inputs)
  {
    seen[key] = true;
    const auto it = current.find(key);
    if (it == current.end())
      add(key, value, "(absent)");
    else if (it->second != value)
      add(key, value, it->second);
  }
  // The resolved keys of a case that sets nothing: every key's default.
  static const std::map<std::string, std::string> defaults = [] {
    const auto inputs = case_inputs(Case{});
    return std::map<std::string, std::string>(inputs.begin(), inputs.end());
  }();
  for (const auto &[key, value] : now.inputs)
    if (!seen.count(key))
    {
      add(key, "(absent)", value);
      const auto d = defaults.find(key);
      out.back().added_at_default = d != defaults.end() && d->second == value;
    }
  return out;
}

std::string describe(const std::vector<CaseDifference> &differences)
{
  std::string text;
  for (const CaseDifference &d : differences)
    text += "  " + d.key + ": " + d.in_checkpoint + " (checkpoint) -> " + d.in_case + " (this case)\n";
  return text;
}

} // namespace magbrush::dem
