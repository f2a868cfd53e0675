// One observable sampled during a run (the normal force on the drum per length, the toner
// mass developed per area, ...), and the two statements a study makes about it:
//
//  * its mean with a STANDARD ERROR. Successive samples of a DEM run are correlated (a chain
//    of beads takes many samples to pass the nip), so the naive σ/√n underestimates the error,
//    by √((1+ρ)/(1−ρ)) for an AR(1) series with lag-one correlation ρ (≈ 4.4× for ρ = 0.9).
//    Block averaging (Flyvbjerg & Petersen 1989) cuts the series into B contiguous blocks
//    much longer than the correlation time; the block means are then nearly independent and
//    their spread / √B estimates the standard error of the mean.
//  * whether it is at a STEADY STATE: the relative drift between the means of the first and
//    the second half of the averaging window, (m₂ − m₁) / |m| — signed, so that a report can
//    say whether a quantity still rises or falls — below a tolerance in size (2 % by
//    default, `statistics.steady_drift`). A series still rising or draining fails it; a
//    stationary one passes once its halves' noise is below the tolerance.
//  * whether a failed test says anything: the drift's own STANDARD ERROR, from each half's
//    block means about that half's own mean (so that a trend between the halves does not
//    inflate it). A drift beyond two of them is a trend; a drift within them is noise, and a
//    window whose two standard errors exceed the tolerance cannot resolve a steady state at
//    that tolerance at all: it needs more samples, not more patience.
#pragma once

#include "dem/measurement.h"


#include <cstddef>
#include <vector>

namespace magbrush::dem {

class SampleSeries
{
public:
  void add(double value) { values_.push_back(value); }
  void clear() { values_.clear(); }
  std::size_t size() const { return values_.size(); }
  const std::vector<double> &values() const { return values_; }
  // The samples, for checkpoints (Measurement::write_state).
  void write_state(StateOut &out) const { out.put_array(values_); }
  void read_state(StateIn &in) { in.get_array(values_); }

  double mean() const; // NaN when empty
  // Standard error of the mean by block averaging over `blocks` contiguous blocks of equal
  // length (the oldest samples that do not fill a block are left out). NaN with fewer than
  // two samples per block.
  double standard_error(std::size_t blocks = default_blocks) const;
  // (mean(second half) − mean(first half)) / |mean|: positive while the quantity rises, negative
  // while it falls (NaN with fewer than 4 samples or a zero mean).
  double drift() const;
  // Standard error of drift(): each half cut into blocks/2 blocks (the newest that fill them),
  // the half's standard error from its block means about its own mean, the two combined, over
  // |mean|. NaN with fewer than two blocks per half or two samples per block, or a zero mean.
  double drift_standard_error(std::size_t blocks = default_blocks) const;

  static constexpr std::size_t default_blocks = 10;

private:
  std::vector<double> values_;
};

// The summary row of a sampled mean: its value, block standard error and, when `steady_test`,
// its drift and the drift's standard error (else NaN: not part of the steady-state verdict).
SummaryValue summarise(const SampleSeries &series, std::size_t blocks, bool steady_test, std::string key,
                       std::string unit, std::string meaning);

// Standard error of a ratio of sums, Σ num / Σ den over the same samples (the tangential over
// the normal force on the drum): the ratio of each block's sums (blocks as for standard_error)
// and the standard error of their mean. NaN with fewer than two blocks of two samples, series
// of different lengths, or a block whose den sums to zero.
double ratio_standard_error(const SampleSeries &num, const SampleSeries &den, std::size_t blocks);

// The same for values that are already independent blocks (the developed image's whole
// periods, toner_development.h): the mean of the blocks, its standard error from their scatter
// (NaN with fewer than two), the drift between the means of the older and the newer half (the
// newer half takes the middle block of an odd count; NaN with fewer than two blocks) and the
// drift's standard error from each half's scatter about its own mean (NaN with fewer than two
// blocks in a half).
SummaryValue summarise_blocks(const std::vector<double> &blocks, bool steady_test, std::string key,
                              std::string unit, std::string meaning);

} // namespace magbrush::dem
