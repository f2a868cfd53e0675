// The brush's height and mass along the sleeve, against the gap it has to pass.
//
// Whether the brush presses the drum at a place is decided by two lengths there: the height its
// chains stand to and the gap. Kawamoto describes the chains standing up as they approach the
// development pole, crushed by the drum in the gap and springing back behind it; where the
// layer piles up in front of the gap (too much supply) the gap is filled from wall to wall.
// This profile gives both, time-averaged over t ≥ nip.average_from in bins of sleeve angle θ
// (the chain profile's bins, nip.chain_bin_angle over ±nip.chain_half_angle):
//
//   tip height   h_tip(θ) = ⟨ max over the carriers in the bin of (|p − S| − R_s + r) ⟩
//                the top of the highest bead above the sleeve surface, averaged over samples;
//   gap          g(θ)     the distance from the sleeve surface to the drum along the radius;
//   layer mass   m(θ)     = ⟨ Σ carrier mass in the bin ⟩ / (R_s Δθ × slab depth)
//                the developer per sleeve area [kg/m²] (its mean over the bin's sleeve area).
//
// h_tip < g: the brush passes free; h_tip = g: it touches (pressed where it would stand taller).
// A brush that stands h_tip before the gap centre and less after it presses the inlet more
// than the outlet at the same gap. Toner is not part of the brush and is not counted.
// File: brush_height.csv.
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/sleeve_angle_bins.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

// One bin of the brush-height profile.
struct BrushHeightBin
{
  double theta = 0.0;      // bin centre, sleeve angle from the line of centres [rad]
  double gap = 0.0;        // sleeve surface to drum surface along the radius at theta [m]
  double tip_height = 0.0; // mean over samples of the highest bead top above the sleeve [m] (NaN: no bead)
  double mass_per_area = 0.0; // mean carrier mass per sleeve area [kg/m²]
  double carriers = 0.0;   // mean carriers in the bin per sample
};

class BrushHeight : public Measurement
{
public:
  explicit BrushHeight(const Case &c);

  const char *name() const override { return "brush height"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;

  long samples() const { return samples_; }
  std::vector<BrushHeightBin> bins() const;
  std::string csv() const;

private:
  NipSettings settings_;
  NipFrame frame_;
  SleeveAngleBins bins_;
  // Per bin, summed over samples: the highest bead top (in samples where the bin holds one),
  // those samples, the carriers' mass and their number.
  std::vector<double> tip_sum_, tip_samples_, mass_sum_, count_sum_;
  std::vector<double> tip_now_; // this sample's highest top per bin (scratch, not state)
  long samples_ = 0;
  double t_first_ = -1.0, t_last_ = -1.0;
  std::vector<bool> species_is_carrier_; // by population index

};

} // namespace magbrush::dem
