// The plug-in interface for what a run measures beyond the time series: profiles along the
// nip, forces on a compression plate, chain statistics. A measurement is handed the whole
// engine state every `interval` of simulated time during the run (never during settling),
// accumulates what it needs, and writes its files (CSV, atomically) at the end of the run.
//
// Measurements only read the engine state; they never change the dynamics, so a run gives
// the same particles with or without them. What they have gathered is part of every
// checkpoint (write_state / read_state, framed by the run: dem/dem_run.cpp), so that a run
// restarted from one writes the files of the whole run, the same bytes as had it never
// stopped, and a run killed between checkpoints loses only what came after the last one.
// A restart that changes what is measured or how (a key of the nip, dma, development,
// flow_report, statistics or compression sections) starts them afresh at the restart time,
// as their files say (the first sample's time).
#pragma once

#include "common/state_stream.h"

#include <limits>
#include <string>
#include <vector>

namespace magbrush::dem {

class DemSystem;

// One number of a measurement's summary: what a study tabulates and plots across its points
// (`magbrush sweep` gathers them from every point's dem/summary.csv).
struct SummaryValue
{
  std::string key;  // unique column name with its unit spelled in it: tma_kg_per_m2, slip_at_gap_centre_m_s
  double value = std::numeric_limits<double>::quiet_NaN();
  // Block-averaged standard error of the mean (NaN: not a sampled mean, or too few samples).
  double standard_error = std::numeric_limits<double>::quiet_NaN();
  // Relative drift between the halves of the averaging window (NaN: not tested for steady
  // state). The run is steady when every tested drift is below statistics.steady_drift.
  double drift = std::numeric_limits<double>::quiet_NaN();
  std::string unit;    // for people: "kg/m^2"
  std::string meaning; // one line
  // Standard error of `drift` (NaN where drift is): a drift beyond two of them is a trend, one
  // within them is noise (dem/measurements/sample_series.h).
  double drift_standard_error = std::numeric_limits<double>::quiet_NaN();
  // A STATE value: an amount the scene holds (the beads in the nip window), not a force or a
  // speed the particles exert. Its drift is what tells a transient (the scene still filling or
  // draining) from a steady state; a run with state values is steady when every state value
  // drifts < statistics.steady_drift and no other tested mean drifts by more than both that
  // tolerance and two of its own standard errors (dem/run_summary.h).
  bool state = false;
};

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
  // The key numbers of the measurement (optional): means with standard errors and drifts, and
  // the physical bounds they are to be judged against (a key ending in "_bound" bounds the key
  // before it, e.g. tma_kg_per_m2 and tma_kg_per_m2_bound).
  virtual std::vector<SummaryValue> summary() const { return {}; }
  // Everything sample() has accumulated (series, sums, the previous sample a difference is
  // taken against), written so that read_state() into a measurement built from the same case
  // continues as if it had sampled all along. Settings and what the constructor derives from
  // the case are not written.
  virtual void write_state(StateOut &out) const = 0;
  virtual void read_state(StateIn &in) = 0;
  // The layout of that state: raised whenever write_state() writes something else, so that a
  // checkpoint written in the old layout starts this measurement afresh (the log says why)
  // instead of being misread. Version 1 is the first layout and is written without a tag.
  virtual int state_version() const { return 1; }
};

} // namespace magbrush::dem
