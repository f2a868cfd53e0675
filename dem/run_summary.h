// dem/summary.csv: the key numbers of every measurement of a run in one table, and the verdict
// on steady state, so that a study (`magbrush sweep`) can tabulate and plot any of them without
// knowing which measurement produced it.
//
//   key,value,standard_error,drift,unit,meaning,measurement
//   normal_force_per_length_N_m,2.31,0.04,0.011,N/m,normal force on the drum per slab depth,nip profile
//   ...
//   steady_state,1,,,1,every tested mean drifts < 2 % between the halves of its window,run
//
// steady_state is 1 when every value tested for drift (a finite drift) is below
// statistics.steady_drift, 0 when one is not, NaN when nothing was tested.
#pragma once

#include "dem/measurement.h"

#include "coupling/case_model.h"

#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

std::string run_summary_csv(const std::vector<std::unique_ptr<Measurement>> &measurements,
                            const StatisticsSettings &statistics);

// Writes <directory>/summary.csv atomically.
void write_run_summary(const std::string &directory, const std::vector<std::unique_ptr<Measurement>> &measurements,
                       const StatisticsSettings &statistics);

} // namespace magbrush::dem
