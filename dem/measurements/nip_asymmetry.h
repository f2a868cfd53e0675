// How symmetric the nip is about the gap centre, as numbers with standard errors.
//
// Kawamoto et al. find the normal pressure on the drum "almost symmetric with respect to the
// distance from the center of the development gap" and the density of touching beads almost
// symmetric, slightly higher at the outlet. A profile plot shows that by eye; a study of what
// moves the pressure needs it as numbers that carry their noise:
//
//   centroid  x̄ = Σ F_n x / Σ F_n              where along the nip the drum is pressed [m]
//   spread    s = √(Σ F_n x² / Σ F_n − x̄²)      how wide the pressed zone is [m]
//   up/down   Σ F_n (x < 0) / Σ F_n (x > 0)     the pressure integral before the centre over after it
//
// and the same with each touching bead weighing one (the touching density). The sums run over
// every bead touching the drum within the profile (x of its contact point, F_n pressing into the
// drum) and every sample of the averaging window; "symmetric" reads |x̄| small against s and
// up/down near 1. The value is the ratio of the window's sums; its standard error comes from the
// same ratio over contiguous blocks of samples (their scatter / √blocks), since successive
// samples are correlated.
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/sample_series.h"

#include <vector>

namespace magbrush::dem {

class NipAsymmetry
{
public:
  // One sample: the contacts' nip coordinates and normal forces.
  void start_sample();
  void add_contact(double x, double normal_force);
  void end_sample();

  // The six numbers above, from `blocks` contiguous blocks of samples.
  std::vector<SummaryValue> summary(std::size_t blocks) const;

  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  // Per-sample sums: F, F x, F x², F upstream, F downstream, n, n x, n x², n upstream, n downstream.
  static constexpr std::size_t sums = 10;
  double current_[sums] = {};
  std::vector<SampleSeries> series_ = std::vector<SampleSeries>(sums);
};

} // namespace magbrush::dem
