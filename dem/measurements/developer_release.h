// Separation at release (Kweon et al. Fig. 6): after the nip, the developer should leave the
// sleeve where two like poles face each other (the radial field between them cancels, and
// gravity and the centrifugal force win); what the sleeve carries on through that sector goes
// back into the pick-up with the toner it lost in the nip and spoils the toner concentration.
// A pole layout is judged by the fraction it separates.
//
// Every sample (case keys dma.release_from, dma.release_to, dma.height, dma.sample_interval,
// dma.average_from): the masses that crossed two radial lines — one before the release sector,
// one after it — within dma.height of the sleeve surface since the previous sample
// (line_flux.h: from positions, by particle id, so independent of any inflow or outflow
// counter). Over the samples from dma.average_from on:
//
//   released fraction = 1 − (mean mass crossing the line after) / (mean mass crossing before),
//
// and both fluxes as areal masses, flux / (sleeve speed × slab length): the developer arriving
// (the DMA the nip passed on, tested for steady state) and the developer carried back. No
// doctor blade is needed: a scene of the release sector alone (cases/kweon_release.yaml) or the
// whole roller both have one.
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/line_flux.h"
#include "dem/measurements/sample_series.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

class DeveloperRelease : public Measurement
{
public:
  explicit DeveloperRelease(const Case &c);
  // The scene calls for it: a sleeve, a periodic slab and a release sector
  // (dma.release_from ≠ dma.release_to).
  static bool applies(const Case &c);

  const char *name() const override { return "developer release"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;
  std::vector<SummaryValue> summary() const override;

  // One sample from the particles (what sample() extracts; tests call it with hand-made scenes).
  void add_sample(double time, const ParticleState &particles);
  std::string csv() const;

private:
  struct Row
  {
    double time = 0, before = 0, after = 0; // masses crossed since the previous sample [kg]
  };

  DmaSettings settings_;
  StatisticsSettings statistics_;
  double R_ = 0, Lz_ = 0, speed_ = 0;
  LineFlux before_line_, after_line_;
  double previous_time_ = -1.0;
  std::vector<Row> rows_;
  // Crossed mass per sample interval, as an areal mass: mass / (dt × speed × L_z).
  SampleSeries arriving_, carried_back_;
};

} // namespace magbrush::dem
