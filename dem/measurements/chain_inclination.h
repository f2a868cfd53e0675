// Inclination of the carrier chains along the sleeve before and after the development gap
// (Kawamoto Fig. 16: chains lean toward the flux lines at the inlet, stand up and are crushed
// in the gap, spring back behind it).
//
// Measured from the particle–particle contacts, time-averaged over t ≥ nip.average_from: each
// touching pair (i, j) gives its branch vector d = x_j − x_i; at the pair's midpoint m the
// local sleeve frame is e_n (radial, away from the roller axis) and e_t (tangent, downstream).
// The in-plane components (d·e_t, d·e_n)/|d| of all contacts in a bin of sleeve angle θ(m)
// build the 2-D fabric tensor F = ⟨u uᵀ⟩; its principal direction is the chain direction:
//
//     inclination α = ½ atan2(2 F_tn, F_nn − F_tt)   ∈ (−90°, 90°]
//
// α = 0: chains along the sleeve normal; α > 0: leaning downstream (tips ahead of roots);
// α < 0: leaning back (tips held back). The anisotropy (λ1 − λ2)/(λ1 + λ2) says how chain-
// like the contact network is (1: all contacts along one line; 0: isotropic). The fabric needs
// no sign convention for d and weighs contacts along the roller axis (no in-plane direction)
// by their small in-plane length squared. File: chain_inclination.csv.
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/sleeve_angle_bins.h"
#include "dem/vector3.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

// One bin of the chain-inclination profile.
struct ChainBin
{
  double theta = 0.0;             // bin centre, sleeve angle from the line of centres [rad]
  double contacts = 0.0;          // mean touching pairs per sample
  double inclination = 0.0;       // principal direction from the sleeve normal [rad] (NaN: none)
  double anisotropy = 0.0;        // (λ1 − λ2)/(λ1 + λ2)
};

class ChainInclination : public Measurement
{
public:
  explicit ChainInclination(const Case &c);

  const char *name() const override { return "chain inclination"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;

  long samples() const { return samples_; }
  std::vector<ChainBin> bins() const;
  std::string csv() const;

private:
  NipSettings settings_;
  NipFrame frame_;
  SleeveAngleBins bins_;
  std::vector<double> ftt_, fnn_, ftn_, count_;
  long samples_ = 0;
  double t_first_ = -1.0, t_last_ = -1.0;
  std::vector<bool> species_is_carrier_; // by population index: toner is not part of the chains

  void add_contact(const Vector3 &a, const Vector3 &d);
};

} // namespace magbrush::dem
