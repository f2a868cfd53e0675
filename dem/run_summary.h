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
// (and a last column, drift_standard_error, on every row.) steady_state is 1 when every value
// tested for drift (a finite drift) is below statistics.steady_drift in size (the drift is
// signed: negative while the quantity falls), 0 when one is not, NaN
// when nothing was tested. The two rows after it say what a 0 means: significant_drift = 1 is
// a trend (the run is not there yet: run longer); significant_drift = 0 with drift_resolution
// above the tolerance is a window too noisy to decide (average more samples: a longer window
// or a deeper slab), not evidence of a transient.
#pragma once

#include "dem/measurement.h"

#include "coupling/case_model.h"

#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

// The run's verdict over every tested mean, written as the three rows above.
struct SteadyStateVerdict
{
  int tested = 0, steady = 0, with_error = 0, trending = 0;
  double resolution = 0.0; // largest 2 × drift standard error
  void add(const SummaryValue &value, double tolerance);
  std::string rows(double tolerance) const;
};

std::string run_summary_csv(const std::vector<std::unique_ptr<Measurement>> &measurements,
                            const StatisticsSettings &statistics);

// Writes <directory>/summary.csv atomically.
void write_run_summary(const std::string &directory, const std::vector<std::unique_ptr<Measurement>> &measurements,
                       const StatisticsSettings &statistics);

} // namespace magbrush::dem
