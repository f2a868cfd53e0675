// The plug-in interface for what a run measures beyond the time series: profiles along the
// nip, forces on a compression plate, chain statistics. A measurement is handed the whole
// engine state every `interval` of simulated time during the run (never during settling),
// accumulates what it needs, and writes its files (CSV, atomically) at the end of the run.
//
// Measurements only read the engine state; they never change the dynamics, so a run gives
// the same particles with or without them. They are not part of checkpoints: after a restart
// they start accumulating afresh from the restart time (say so in their output).
#pragma once

#include <string>

namespace magbrush::dem {

class DemSystem;

class Measurement
{
public:
  virtual ~Measurement() = default;
  virtual const char *name() const = 0;
  // Simulated time between samples [s] (0 = every step).
  virtual double interval() const = 0;
  // Called after a step, at t = system.time() ≥ 0, every interval().
  virtual void sample(const DemSystem &system) = 0;
  // Writes the results into `directory` (the run's output folder) at the end of the run,
  // and when the run stops on a stability guard (what was gathered so far is kept).
  virtual void write(const std::string &directory) const = 0;
};

} // namespace magbrush::dem
