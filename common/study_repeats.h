// The repeats of a study point (`magbrush sweep --repeats N`): the same point run N times with
// other random seeds (other bead sizes, positions and charges drawn from the same case). Their
// mean, with the standard error taken from the spread between the repeats, is the honest
// error bar of a short or transient run: a run's own block-averaged standard error sees only
// the noise within its window, and in a growing quantity (the TMA of a development cell)
// it includes the trend instead of the realisation-to-realisation scatter.
//
//   value          = mean over the repeats that have it
//   standard_error = sample standard deviation / √n (n ≥ 2; NaN with one repeat)
//   drift          = mean of the repeats' drifts; its standard error that of a mean of
//                    independent drifts, √(Σ se²) / n
// The run's verdicts are combined, not averaged: steady_state is 1 only when every repeat is
// steady (NaN when any has no verdict), significant_drift 1 when any repeat has a trend, and
// drift_resolution the largest of the repeats' (the coarsest window decides).
#pragma once

#include "common/study_table.h"

#include <vector>

namespace magbrush {

// The summary of one point from the summaries of its repeats (each a run's dem/summary.csv);
// the keys in the order first seen. A repeat without a key (a failed run) does not count for it.
std::vector<SummaryRow> mean_of_repeats(const std::vector<std::vector<SummaryRow>> &repeats);

} // namespace magbrush
