// The developer the doctor blade lets through (Kweon et al. Fig. 5–7): the developer mass per
// area (DMA) on the sleeve between the blade and the nip, which sets how much developer — and
// so how much toner — reaches the development nip.
//
// Every sample (case keys dma.*, case/case_keys_measurements.cpp):
//  * DMA, areal form: the mass of the particles in the window of width dma.window centred
//    dma.after_blade past the blade's tip (in the sense the sleeve turns), within dma.height
//    of the sleeve surface, over the sleeve area of the window, R Δθ L_z;
//  * DMA, flux form: the mass that crossed the window's centre line since the previous sample
//    (line_flux.h, counted from positions by particle id) per time, over v_sleeve L_z. A layer
//    riding on the sleeve gives the areal form; a layer that slips behind the sleeve gives
//    less. At a steady state both are constant;
//  * the toner concentration in the window (toner mass / carrier mass), when there is toner;
//  * the blade's load per slab length: the force the particles exert on the blade, resolved
//    along the radius through its tip (pushing it away from the sleeve: +) and along the
//    sleeve's motion there;
//  * the developer held in front of the blade: the mass in the sector dma.front_window just
//    before the tip, at any distance from the sleeve, per slab length (Kweon Fig. 5: the
//    accumulation that the auxiliary guide wall removes);
//  * the speed of the developer in the blade's gap against the sleeve's: the mass-weighted
//    angular speed of the particles under the tip (within gap / R of it on either side, below
//    the gap's height) over the sleeve's. 1: the sleeve carries the layer through the gap;
//    below 1 the sleeve slides under a layer the blade and the pile in front hold back, and
//    the DMA falls with it (the blade jams: docs/regulation.md, the smooth sleeve);
// (The fraction released after the nip, dma.release_*, is developer_release.h's.)
//
// The summary (dem/summary.csv, gathered by `magbrush sweep`) gives the means over the samples
// from dma.average_from with block-averaged standard errors and the steady-state drift, and
// the bound DMA ≲ ρ_bulk × gap: a layer cannot leave the blade's gap denser than a random close
// packing (solid fraction 0.64) moving at the sleeve speed; ρ_bulk = 0.64 ρ_carrier (1 + TC),
// the toner filling the voids.
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/line_flux.h"
#include "dem/measurements/sample_series.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

class DeveloperMassPerArea : public Measurement
{
public:
  explicit DeveloperMassPerArea(const Case &c);
  // The scene calls for it: a sleeve, a periodic slab and a doctor blade.
  static bool applies(const Case &c);

  const char *name() const override { return "developer mass per area"; }
  double interval() const override { return settings_.sample_interval; }
  int state_version() const override { return 2; } // 2: the gap's speed ratio
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;
  std::vector<SummaryValue> summary() const override;

  // One sample from the particles and the force on the blade [N] (what sample() extracts
  // from the engine; tests call it with hand-made scenes).
  void add_sample(double time, const ParticleState &particles, const Vector3 &force_on_blade);

  // The blade tip's roller angle [rad] and the bound ρ_bulk × gap [kg/m²].
  double blade_angle() const { return blade_angle_; }
  double dma_bound() const { return bulk_density_ * gap_; }
  std::string csv() const;

private:
  struct Row
  {
    double time = 0, dma = 0, dma_flux = 0, toner_concentration = 0;
    double blade_radial = 0, blade_along = 0; // [N/m]
    double held_in_front = 0;                 // [kg/m]
    double gap_speed_ratio = 0;               // developer in the gap / sleeve (NaN: gap empty)
  };

  DmaSettings settings_;
  StatisticsSettings statistics_;
  double R_ = 0, Lz_ = 0, sense_ = 1, speed_ = 0;
  double blade_angle_ = 0, gap_ = 0, bulk_density_ = 0;
  std::string blade_name_;
  std::vector<char> is_toner_; // per population index
  LineFlux centre_line_;
  double previous_time_ = -1.0;
  std::vector<Row> rows_;
  SampleSeries dma_, dma_flux_, concentration_, blade_radial_, blade_along_, held_, gap_speed_;

  // Angle of p from `angle` in the sense the sleeve turns, in (−π, π].
  double angle_from(double px, double py, double angle) const;
};

} // namespace magbrush::dem
