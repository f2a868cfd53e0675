// The nip as a time series, from t = 0 (every sample, not only the averaging window): the
// bead budget of the periodic slab and the load on the drum. One row per sample in
// nip_time_series.csv:
//
//  * beads: particles in the slab (constant unless the case has an inflow or an outflow);
//    lost: beads with a non-finite position, inside the sleeve, or farther from the
//    roller axis than the magnetic grid reaches (nothing holds them any more);
//  * the bead budget of the nip window |θ| ≤ nip.chain_half_angle (sleeve angle): beads in
//    it, and the running counts of beads that entered it across its upstream edge and left it
//    across its downstream edge (net, per bead, tracked by stable id). Mass conservation
//    reads in_window(t) = in_window(0) + entered(t) − left(t); in a steady state entered and
//    left grow at the same rate (the flux through the nip);
//  * drum: beads touching it, total normal and tangential force on it [N] (signs as in
//    nip_profile.h), and the mean slip of the touching beads within one bin of the gap centre.
//
// Its summary is the STATE of the nip for the steady-state verdict (dem/run_summary.h): the
// mean number of beads in the window over the averaging window (t >= nip.average_from), with
// its block standard error and drift. While the sleeve still fills the nip (or a placed load
// drains through it) this count moves by tens of per cent; in a steady state it holds, and it
// is counted over thousands of beads, so its halves agree far better than the drum forces'.
#pragma once

#include "dem/dem_system.h"
#include "dem/measurement.h"
#include "dem/measurements/nip_frame.h"

#include "case/case_model.h"

#include <cstdint>
#include <string>
#include <vector>

namespace magbrush::dem {

struct NipBudgetRow
{
  double time = 0.0;
  long beads = 0, lost = 0, in_window = 0, entered = 0, left = 0;
  long drum_touching = 0;
  double drum_normal_force = 0.0, drum_tangential_force = 0.0; // [N]
  double centre_slip = 0.0;                                    // [m/s] (NaN: no bead there)
};

class NipTimeSeries : public Measurement
{
public:
  explicit NipTimeSeries(const Case &c);

  const char *name() const override { return "nip time series"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;
  std::vector<SummaryValue> summary() const override;

  // The bead budget from plain arrays (tests): ids, positions, radii at one time.
  void add_beads(double time, const std::vector<std::int32_t> &ids, const std::vector<Vector3> &positions,
                 const std::vector<double> &radii);

  const std::vector<NipBudgetRow> &rows() const { return rows_; }
  std::string csv() const;

private:
  NipSettings settings_;
  StatisticsSettings statistics_;
  NipFrame frame_;
  double lost_radius_ = 0.0;             // beyond this distance from the roller axis a bead is lost [m]
  std::vector<std::int8_t> region_;      // by id: −1 upstream, 0 in the window, +1 downstream, 2 unseen
  long entered_ = 0, left_ = 0;
  std::vector<NipBudgetRow> rows_;
  std::vector<WallContactRecord> records_;
  std::vector<std::int32_t> ids_;
  std::vector<Vector3> positions_;
  std::vector<double> radii_;

  std::int8_t region_of(const Vector3 &p) const;
};

} // namespace magbrush::dem
