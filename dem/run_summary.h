// dem/summary.csv: the key numbers of every measurement of a run in one table, and the verdict
// on steady state, so that a study (`magbrush sweep`) can tabulate and plot any of them without
// knowing which measurement produced it.
//
//   key,value,standard_error,drift,unit,meaning,measurement
//   normal_force_per_length_N_m,2.31,0.04,0.011,N/m,normal force on the drum per slab depth,nip profile
//   ...
//   steady_state,1,,,1,every tested mean drifts < 2 % between the halves of its window,run
//   significant_drift,0,,,1,0 of 3 tested means drift by more than two standard errors,run
//   drift_resolution,0.012,,,1,two standard errors of the drift of the noisiest tested mean,run
//
// (and two last columns on every row: drift_standard_error, and state = 1 for a state value.)
// The verdict, steady_state, is 1, 0 or NaN (nothing tested), by one of two rules:
//
//  * without STATE values (SummaryValue::state): every value tested for drift (a finite
//    drift) is below statistics.steady_drift in size (the drift is signed: negative while the
//    quantity falls).
//  * with state values (the nip: the beads in its window): every state value drifts less than
//    the tolerance, and no other tested mean drifts by more than both the tolerance and two of
//    its own standard errors. Why: the state says whether the scene still fills or drains; a
//    force sampled from ~150 touching beads fluctuates by ~5 % per ms (the nip's drum force),
//    so the halves of a 15 ms window differ by a few per cent from noise alone, and requiring
//    them to agree within 2 % tests the window's length, not the state (docs/nip.md). A force
//    that trends beyond its noise still fails the run.
//
// The two rows after it say what a 0 means, and how far the verdict can be trusted:
// significant_drift = 1 is a trend (the run is not there yet: run longer); significant_drift
// = 0 with drift_resolution above the tolerance is a window too noisy to decide (average more
// samples: a longer window or a deeper slab), not evidence of a transient. drift_resolution is
// also what a 1 by the second rule means for the forces: no trend larger than it.
#pragma once

#include "dem/measurement.h"

#include "case/case_model.h"

#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

// The run's verdict over every tested mean, written as the three rows above.
struct SteadyStateVerdict
{
  int tested = 0, steady = 0, with_error = 0, trending = 0;
  int states = 0, steady_states = 0; // state values tested, and those below the tolerance
  int observables_beyond = 0;        // other tested means past the tolerance AND past 2 standard errors
  double resolution = 0.0;           // largest 2 × drift standard error of the tested means but the states
  void add(const SummaryValue &value, double tolerance);
  std::string rows(double tolerance) const;
  // 1 steady, 0 not, NaN nothing tested (the rules above).
  double verdict() const;
};

std::string run_summary_csv(const std::vector<std::unique_ptr<Measurement>> &measurements,
                            const StatisticsSettings &statistics);

// Writes <directory>/summary.csv atomically.
void write_run_summary(const std::string &directory, const std::vector<std::unique_ptr<Measurement>> &measurements,
                       const StatisticsSettings &statistics);

} // namespace magbrush::dem
