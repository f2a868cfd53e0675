// Profiles along the development nip of the beads touching the drum (Kawamoto Fig. 17–20),
// time-averaged over the steady state (samples at t ≥ nip.average_from):
//
//  * slip speed: velocity of the bead's material at its contact point on the drum minus the
//    velocity of the drum surface there, tangential component along the downstream tangent
//    of the drum (the paper: equal to the relative surface speed 0.135 m/s at the gap centre);
//  * chain speed: the same with the bead's centre instead of its contact point, i.e. how fast
//    the chain's end moves over the drum whether it slides or rolls. Kawamoto's Fig. 17 is
//    "the slip speed of the chains", without saying which of the two; a bead that rolls over
//    the drum moves its chain along while its contact point stands still on the drum, so the
//    two differ by the spin ω × r;
//  * normal and tangential pressure on the drum: Σ (force of the touching beads on the drum,
//    normal component pushing into the drum / tangential component downstream) per bin, over
//    the drum surface of the bin (arc length of the bin on the drum × slab depth);
//  * density of the beads touching the drum [1/mm²] and the mean normal force per bead;
//  * which contacts slide: a contact whose contact point moves over the drum faster than a
//    tenth of the relative surface speed (in any tangential direction, the slab depth
//    included) slides, and Coulomb friction then pulls the drum along its slip with μ F_n.
//    The shares of the normal force carried by sliding contacts (S) and by sliding contacts
//    weighted with the downstream cosine of their slip (D) bound the ratio tangential/normal
//    from the kinematics alone: μ (D − (1 − S)) ≤ Σ F_t / Σ F_n ≤ μ (D + (1 − S)), since a
//    contact that sticks carries at most μ F_n either way. The bound is independent of the
//    forces the ratio is made of (tests/scenes/nip asserts it on the reduced nip).
//
// Bins: centred on the gap centre, width nip.bin_width, along x (NipFrame: distance from the
// gap centre along the common tangent, positive downstream); a contact is binned by the x of
// its contact point on the drum surface. Each row also gives the drum arc length and angle
// and the sleeve angle of its bin centre.
//
// Files (in the run's output folder): nip_profile.csv (one row per bin, units in the header)
// and nip_summary.csv (key numbers: slip at the gap centre against the relative surface speed,
// peak normal pressure against the magnetic pressure B²/2μ0 at the gap centre, tangential /
// normal, touching density, samples and averaging window; how symmetric the pressure and the
// touching beads are about the gap centre: nip_asymmetry.h).
#pragma once

#include "dem/dem_system.h"
#include "dem/measurement.h"
#include "dem/measurements/nip_asymmetry.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/sample_series.h"
#include "dem/vector3.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

// One bead touching the drum at one sample: what the profile needs from the engine.
struct DrumContact
{
  Vector3 position, velocity, angular_velocity; // bead centre, its velocity and spin
  double radius = 0.0;
  Vector3 force_on_wall;                          // the force the bead exerts on the drum [N]
};

// The per-contact quantities in the nip frame.
struct DrumContactInFrame
{
  double x = 0.0;          // nip coordinate of the contact point on the drum [m]
  double slip = 0.0;       // tangential slip speed, bead relative to drum, downstream > 0 [m/s]
  double normal = 0.0;     // force pressing into the drum [N]
  double tangential = 0.0; // force on the drum along the downstream tangent [N]
  double slip_speed = 0.0; // |tangential velocity of the bead's contact point relative to the drum|, 3D [m/s]
  double chain_speed = 0.0; // bead centre velocity relative to the drum surface at q, downstream > 0 [m/s]
};
DrumContactInFrame resolve_drum_contact(const NipFrame &frame, const DrumContact &c);

// Time-averaged value of one bin.
struct NipBin
{
  double x = 0.0, x_lo = 0.0, x_hi = 0.0;   // centre and edges [m]
  double area = 0.0;                         // drum surface of the bin in the slab [m²]
  double touching = 0.0;                     // mean number of touching beads per sample
  double density = 0.0;                      // touching beads per area [1/m²]
  double normal_pressure = 0.0;              // [Pa]
  double tangential_pressure = 0.0;          // [Pa]
  double slip = 0.0, slip_std = 0.0;         // mean over touching beads and its spread [m/s] (NaN: none)
  double chain_speed = 0.0;                  // mean bead-centre speed over the drum [m/s] (NaN: none)
  double normal_force_per_bead = 0.0;        // [N] (NaN: none)
  long contacts = 0;                         // contact samples accumulated
};

class NipProfile : public Measurement
{
public:
  explicit NipProfile(const Case &c);

  const char *name() const override { return "nip profile"; }
  int state_version() const override { return 3; } // 2: with the asymmetry's series; 3: each bin's pressure series
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;

  // The same accumulation from hand-made contacts (what sample() extracts from the engine).
  void add_sample(double time, const std::vector<DrumContact> &contacts);

  const NipFrame &frame() const { return frame_; }
  long samples() const { return samples_; }
  std::vector<NipBin> bins() const;
  // Key numbers over the averaging window.
  double slip_at_gap_centre() const;          // mean slip of the centre bin [m/s]
  double chain_speed_at_gap_centre() const;   // mean bead-centre speed over the drum, centre bin [m/s]
  double tangential_over_normal() const;      // Σ F_t / Σ F_n over every bin
  double peak_normal_pressure() const;        // [Pa]
  // Contacts slipping faster than this over the drum are sliding [m/s]: a tenth of the
  // relative surface speed of sleeve and drum (1 mm/s when that is zero). A stuck contact's
  // point only creeps with the elastic tangential spring, far slower.
  double sliding_speed() const;
  // Over the averaging window and the profile: S = Σ_sliding F_n / Σ F_n and
  // D = Σ_sliding F_n (slip / slip_speed) / Σ F_n (the downstream cosine of each slip).
  double sliding_share() const;
  double sliding_downstream_share() const;
  // |B| of the applied field at the gap centre [T] when the case's magnetic grid could be read
  // at construction (else NaN); the magnetic pressure scale is B²/2μ0.
  double gap_centre_field() const { return gap_field_; }

  std::string csv() const;
  std::string summary_csv() const;
  // The key numbers for studies: the forces on the drum, the touching beads and the slip at
  // the gap centre with block-averaged standard errors and their drift (steady state).
  std::vector<SummaryValue> summary() const override;

private:
  NipSettings settings_;
  StatisticsSettings statistics_;
  NipFrame frame_;
  std::size_t drum_wall_ = 0;
  int bins_half_ = 0;                 // bins k = −bins_half_ … +bins_half_
  std::vector<double> fn_, ft_, slip_, slip2_, chain_;
  std::vector<long> count_;
  double fn_sliding_ = 0.0, fn_sliding_downstream_ = 0.0; // Σ F_n, Σ F_n cos over sliding contacts
  long samples_ = 0;
  double t_first_ = -1.0, t_last_ = -1.0;
  // Per-sample totals over the profile (for standard errors and the steady-state test).
  SampleSeries normal_force_, tangential_force_, touching_, centre_slip_, centre_chain_;
  // Per sample and bin, the normal pressure [Pa] (the standard errors of the peak and of the
  // centre bin's pressure), and the centre bin's touching beads (its density's error).
  std::vector<SampleSeries> bin_pressure_;
  SampleSeries centre_touching_;
  std::vector<double> bin_area_;      // drum surface of each bin in the slab [m²]
  std::vector<double> sample_fn_;     // one sample's normal force per bin (reused)
  NipAsymmetry asymmetry_; // centroid, spread and up/down ratio of the pressure and the touching beads
  double gap_field_;
  std::vector<WallContactRecord> records_; // reused between samples
  std::vector<DrumContact> contacts_;

  int bin_of(double x) const;         // −1: outside the profile
  std::size_t peak_bin() const;       // the bin of the largest mean normal pressure
  std::size_t find_drum_wall(const DemSystem &system) const;
};

} // namespace magbrush::dem
