// One DEM run of a case, as `magbrush dem` does it:
//
//   insert the populations → settle → loop { step; time series; snapshots; checkpoints;
//   progress line } → final checkpoint → log of the time spent per phase and force term
//
// or, with a checkpoint, restart at its step and continue bit-identically. The run owns the
// outputs: <output.directory>/dem/{particles.xdmf, snapshots/, time_series.csv,
// checkpoint.bin, checkpoint.previous.bin}.
//
// Checkpoints are written every dem.checkpoint_interval of simulated time, every
// dem.checkpoint_wall_interval of wall time and at the end; each replaces checkpoint.bin
// atomically and the one before it is kept as checkpoint.previous.bin. A checkpoint holds the
// measurements' accumulated state too, so a restarted run writes the files of the whole run;
// their files are written at every checkpoint as well, so a stopped run leaves them to there.
// A restart checks that the checkpoint was written by this case (restart_check.h).
#pragma once

#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/measurement.h"
#include "dem/snapshot_writer.h"

#include "case/case_model.h"

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

struct RunOptions
{
  std::string restart_file;  // continue from this checkpoint ("" = fresh run)
  // Continue from the output folder's own checkpoint.bin when there is one (a run stopped by
  // a time limit, by hand or by a crash), else start afresh. Not with restart_file.
  bool resume = false;
  bool restart_anyway = false; // restart even when the checkpoint's case differs beyond run control
  std::string output_dir;    // "" = <case.output.directory>/dem
  int threads = 0;           // 0 = case.dem.threads, then the OpenMP default
  double progress_interval = 5.0; // seconds of wall time between progress lines
};

class DemRun
{
public:
  // Builds the engine with every registered force term the scene needs
  // (dem/force_terms/force_term_registry.h).
  DemRun(const Case &c, const RunOptions &options, std::ostream &log);

  // The engine, e.g. to replace a force term by one with other settings before run().
  DemSystem &system() { return *system_; }
  // Each registered force term: on, or off and why.
  const std::vector<ForceTermChoice> &force_term_choices() const { return force_terms_; }
  // A measurement sampled during the run and written into output_dir() at its end.
  void add_measurement(std::unique_ptr<Measurement> m) { measurements_.push_back(std::move(m)); }
  const std::vector<std::unique_ptr<Measurement>> &measurements() const { return measurements_; }

  // Inserts (or restarts), settles and runs to case.dem.duration. Throws StabilityError
  // after keeping the last good checkpoint.
  void run();

  const std::string &output_dir() const { return out_dir_; }
  std::string checkpoint_path() const;
  // Checkpoints written by this run so far.
  long checkpoints_written() const { return checkpoints_; }

private:
  Case case_;
  RunOptions options_;
  std::ostream &log_;
  std::string out_dir_;
  std::unique_ptr<DemSystem> system_;
  std::vector<std::unique_ptr<Measurement>> measurements_;
  std::vector<ForceTermChoice> force_terms_;
  CheckpointIdentity identity_; // of case_, written into every checkpoint
  long checkpoints_ = 0;
  long last_checkpoint_step_ = -1;

  // Refuses a checkpoint of another scene (unless --restart-anyway); returns why the
  // measurements must start afresh ("" = they continue the checkpoint's).
  std::string check_restart_case() const;
  void write_measurement_states(StateOut &out) const;
  void read_measurement_states(StateIn &in, const std::string &afresh_because);
  void write_checkpoint();
  void log_setup() const;
  void log_timings(double wall) const;
  void take_own_checkpoint();
  // Every measurement's files and the run's summary; so_far: at a checkpoint (not logged).
  void write_measurements(bool so_far = false) const;
};

} // namespace magbrush::dem
