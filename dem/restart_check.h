// Whether a checkpoint may continue under the case at hand.
//
// A checkpoint carries the resolved inputs of the case that wrote it (checkpoint_file.h).
// A restart compares them key by key with the case it runs under:
//   * run control — how long to run, how often to write, where, on how many threads — may
//     differ: the state is the same scene, continued (the differences are logged);
//   * anything else (a particle count, a material, a wall, a field, a time step, a magnetic
//     setting) means the checkpoint is not the state of this case: the restart is refused
//     with the list of keys and both values, unless the user says --restart-anyway.
#pragma once

#include "dem/checkpoint_file.h"

#include <string>
#include <vector>

namespace magbrush::dem {

struct CaseDifference
{
  std::string key;            // the resolved key path, e.g. "populations[0].count"
  std::string in_checkpoint;  // "(absent)" when only the case has it
  std::string in_case;        // "(absent)" when only the checkpoint has it
  bool run_control = false;   // may differ in a restart
  // Only this case has the key, at its default value: a key the schema gained after the
  // checkpoint was written (its default is what the older program did), not a change.
  bool added_at_default = false;
};

// Run-control keys: dem.duration, the output, sample and checkpoint intervals, threads,
// the output directory and formats, the stored fields' folder (a sweep keeps them per digest), and every key of the measurement-only sections (nip.*,
// dma.*, development.*, flow_report.*, statistics.*: windows, sampling, averaging).
bool is_run_control_key(const std::string &key);
// Keys that say what a measurement samples and how it judges it (the measurement-only sections
// and compression.sample_interval / map_interval): a restart that changes one starts the
// measurements afresh rather than continuing the checkpoint's (dem/measurement.h).
bool is_measurement_key(const std::string &key);

// The keys whose values differ between the checkpoint's case and this one, in the order of
// the checkpoint's keys (then those only this case has, flagged when at their defaults).
std::vector<CaseDifference> case_differences(const CheckpointIdentity &checkpoint, const CheckpointIdentity &now);

// "  key: checkpoint value -> case value" lines.
std::string describe(const std::vector<CaseDifference> &differences);

} // namespace magbrush::dem
