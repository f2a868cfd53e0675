// The DEM force term of the induced-dipole magnetics (Kawamoto A8–A11, Kweon eq. 2–5): plugs
// the magnetics library (magnetics/induced_dipoles.h) into the engine's ForceTerm interface
// (dem/force_term.h). On when the case has an applied field and a carrier population.
//
// Only carrier beads (populations of kind carrier) take part; each gets μr and M_s from its
// population's material. Per step, the term gathers the carriers' positions into compact
// arrays and then, Kawamoto's "magnetics every 5 µs while stepping at 20 ns":
//   * a full evaluation when the refresh interval elapsed (or nothing is held yet);
//   * when some beads moved more than the staleness fraction of their radius: a local
//     refresh around them (StalenessMode::local) or a full evaluation (absolute);
//   * otherwise the held forces of the last evaluation, rescaled by (s(t)/s_held)² while
//     the applied field ramps (linear beads: p ∝ B, F ∝ B², exact).
//
// Particles entering or leaving (the inflow / outflow exchange) fire no evaluation of their
// own (MagneticSettings::defer_exchange): with admit_exchange they are admitted at the next
// step into the held state (the leavers become inert holes until the lists are rebuilt, the
// newcomers join the kept cells and lists, a local refresh solves around both); otherwise,
// or where that cannot be done, they join the next full evaluation, meanwhile the leavers
// stay frozen sources and the newcomers feel the field and their held neighbours.
//
// The compact carrier order is the magnetics' own, fixed when the carriers are selected: the
// engine's spatial re-sorting only changes which engine index each compact bead reads, so
// the magnetic neighbour lists, cells and dipoles survive it. Positions are unwrapped along
// periodic axes (each bead keeps the image nearest to its previous position), so a wrap by
// the engine is no jump for the magnetics either.
#pragma once

#include "dem/force_term.h"
#include "magnetics/induced_dipoles.h"
#include "magnetics/two_sphere_correction.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_model.h"

#include <array>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class MagneticForceTerm : public dem::ForceTerm
{
public:
  // `box` = the DEM's periodic lengths (0 = open); `settings` usually
  // MagneticSettings::from_case(c.dem). In a slab periodic along exactly two axes the slab
  // tail correction is switched on unless `slab_tail` is false (docs/magnetics.md: a hard
  // cutoff leaves ~30 % force errors at 8 diameters there).
  MagneticForceTerm(const Case &c, MagneticSettings settings, const AppliedMagneticField &field,
                    const std::array<double, 3> &box, bool slab_tail = true);

  const char *name() const override { return "magnetic dipoles"; }
  // For the engine's log, under the term's time: how often the magnetics were evaluated and
  // why, and where their time went (full evaluations by phase, local refreshes, admissions,
  // the close pairs' live forces, the staleness checks).
  std::string cost_note() const override;
  void add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t) override;
  // The steps that hold (no evaluation, exchange or ramp due) run inside the engine's team,
  // also while newcomers wait for admission in empty space (a fed brush: nearly always).
  // A step whose last look found nothing stale, and whose beads cannot have moved enough
  // since to change that (`step_move` summed), does not look again (a quiet step).
  bool add_forces_in_team_if_held(const dem::ParticleState &state, dem::ForceBuffers &forces, double t,
                                  double step_move) override;
  void particles_reordered(const std::vector<std::int32_t> &order) override;
  // Checkpoint: the carrier selection and order, the unwrapped positions, the held forces and
  // ramp, the counters, and the magnetics' whole held state (InducedDipoles::write_state), as
  // one block. A checkpoint written under other magnetic settings restores nothing: the next
  // step evaluates afresh (restored_state() is then false).
  void write_state(dem::CheckpointWriter &out) const override;
  void read_state(dem::CheckpointReader &in) override;
  bool restored_state() const { return restored_; }
  // Carriers left or entered: the leavers are dropped from the compact order (the others
  // keep their place, dipoles and unwrapped positions), the newcomers that are carriers are
  // appended — at the next step, which then solves in full (warm-started), or with
  // MagneticSettings::defer_exchange (the default) at the next full evaluation, the leavers
  // staying frozen sources until then; an exchange that moved nothing changes nothing.
  void particles_changed(const std::vector<std::int32_t> &origin) override;

  // Statistics of the last full evaluation, and of the last local refresh.
  const MagneticStats &last_stats() const { return stats_; }
  const MagneticStats &last_local_stats() const { return local_stats_; }
  const MagneticStats &last_admission_stats() const { return admit_stats_; }
  // A disabled term adds nothing (benchmarks compare settings in one system).
  void set_enabled(bool enabled) { enabled_ = enabled; }
  // With false, every step goes through add_forces() outside the engine's team, as before the
  // held steps ran inside it (benchmarks and tests compare the two: the same bits).
  void set_held_steps_in_team(bool on) { held_steps_in_team_ = on; }
  // Steps whose forces were added inside the team so far (this process; not checkpointed),
  // and of those the quiet ones (no gather, no check: their moves were bounded).
  long steps_held_in_team() const { return steps_in_team_; }
  // Of those, the steps with newcomers waiting for admission; and how many wait now.
  long steps_held_in_team_waiting() const { return steps_in_team_waiting_; }
  std::size_t waiting_newcomers() const { return pending_ ? newcomers_.size() : 0; }
  long quiet_steps() const { return quiet_steps_; }
  // With false, every step in the team gathers and checks (benchmarks and tests compare: the
  // same bits).
  void set_quiet_steps(bool on) { quiet_steps_on_ = on; }
  // For benchmarks: keep the compact order as the exchanges leave it instead of following the
  // engine's (follow_engine_order()).
  void set_follow_engine_order(bool on) { follow_engine_order_on_ = on; }
  // Full evaluations (compute) and local refreshes so far.
  long evaluations() const { return evaluations_; }
  long local_refreshes() const { return local_refreshes_; }
  // Full evaluations by cause: first / bead count changed / the field came on, interval
  // elapsed, beads moved
  // (absolute mode, or a local refresh that could not stand in for a full one), and how
  // many of those found no applied field (nothing solved).
  struct RefreshCountsStored // (the checkpoint's layout)
  {
    long first = 0, interval = 0, moved = 0, zero_field = 0;
    // Wall time [s] in full evaluations, in local refreshes (including attempts that fell
    // back to a full one), and in the per-step staleness checks; and the beads solved again
    // (the regions) summed over the local refreshes.
    double full_s = 0.0, local_s = 0.0, check_s = 0.0;
    double cold_s = 0.0; // of full_s: the run's first evaluation (cell tables, lattice sums)
    long region_beads = 0;
    // The full evaluations' phases summed [s] (MagneticStats): lists / cells, applied field +
    // tensors, far field, sweeps, forces; and how many rebuilt the lists.
    double lists_s = 0.0, tensors_s = 0.0, far_s = 0.0, sweeps_s = 0.0, forces_s = 0.0;
    long rebuilds = 0;
  };
  struct RefreshCounts : RefreshCountsStored // (the rest is written at the block's end)
  {
    // Of `moved`: the local refresh fell back to a full evaluation because the lists expired
    // / because the region exceeded local_region_limit of the beads.
    long moved_lists = 0, moved_region = 0;
    // Full evaluations that took in particles entered or left (inflow, outflow): of `first`
    // without MagneticSettings::defer_exchange (one per exchange), of any cause with it.
    long set_changed = 0;
    // MagneticSettings::admit_exchange: exchanges admitted at the next step without a full
    // evaluation (InducedDipoles::admit), their wall time [s] and the beads solved again.
    long admitted = 0;
    double admit_s = 0.0;
    long admit_region_beads = 0;
    // MagneticSettings::hold_dipoles: wall time [s] of the close pairs' per-step forces.
    double live_s = 0.0;
  };
  const RefreshCounts &refresh_counts() const { return counts_; }
  const InducedDipoles &dipoles() const { return dipoles_; }
  // The engine index of each bead in the magnetics' compact order (kLeft for a carrier that
  // left and waits to be dropped).
  const std::vector<std::uint32_t> &compact_carriers() const { return carrier_; }
  // The magnetic forces this term added at its last step, by engine index (0 for toner):
  // `fx` etc. are resized to the engine's particle count and overwritten [N].
  void last_forces(std::vector<double> &fx, std::vector<double> &fy, std::vector<double> &fz) const;
  // The dipoles held at this step, by engine index (3 per particle, 0 for toner and for
  // carriers waiting for admission) [A m²], scaled with the ramp as the held forces are.
  void held_dipoles(std::vector<double> &p) const;

private:
  // Per population: is it a carrier, and its material's μr and M_s (copied from the case).
  struct Species
  {
    bool carrier = false;
    double mu_r = 1.0, saturation_magnetisation = 0.0;
  };
  std::vector<Species> species_;
  // Appends particle i (a carrier of population `species`) to the compact bead arrays.
  void append_bead(const dem::ParticleState &state, std::size_t i, const Species &species);
  std::size_t state_size_ = 0;
  InducedDipoles dipoles_;
  AppliedMagneticField field_;
  std::array<double, 3> box_;
  MagneticStats stats_, local_stats_, admit_stats_;
  long evaluations_ = 0, local_refreshes_ = 0;
  RefreshCounts counts_;

  // Compact carrier arrays in the magnetics' own order; carrier_[k] = engine index of
  // compact bead k (updated on every engine re-sort).
  std::vector<std::uint32_t> carrier_;
  std::vector<double> x_, y_, z_, radius_, mu_r_, Ms_, fx_, fy_, fz_, tx_, ty_, tz_;
  // hold_dipoles: this step's change of the close pairs' forces since their evaluation (3 per
  // compact bead, InducedDipoles::live_pair_changes), or null.
  const std::vector<double> *live_ = nullptr;
  bool must_refresh_ = true;
  // Engine indices of particles that entered since the last step (particles_changed), kept
  // through re-sorting; the carriers among them join the compact order at the next step.
  std::vector<std::uint32_t> newcomers_;
  bool changed_ = false;
  // MagneticSettings::defer_exchange: a compact bead whose particle left keeps its place, its
  // last position and its dipole (a frozen source, carrier_ = kLeft) until the next full
  // evaluation compacts the set and admits the newcomers (`pending_`).
  static constexpr std::uint32_t kLeft = 0xffffffffu;
  std::size_t left_ = 0;
  std::size_t holes_ = 0; // of left_: admitted leavers, inert holes (admit_exchange)
  bool pending_ = false;
  // More newcomers than this are admitted at once (each waiting one costs a sum over all
  // carriers per step).
  static constexpr std::size_t kMaxWaiting = 64;
  // Meanwhile each waiting carrier is induced by the applied field and its neighbours' held
  // dipoles and feels their pair forces (and they its), every step (add_waiting_forces);
  // the engine indices and forces added at the last step (for last_forces).
  std::vector<std::uint32_t> waiting_, neighbours_, candidates_; // add_waiting_forces()
  std::vector<double> waiting_f_;
  // `corrected`: the two-sphere correction of a waiting carrier's close pairs, through a
  // two-bead state (the neighbour, the newcomer) reused every time.
  TwoSphereCorrection waiting_correction_;
  std::vector<double> carrier_beta_; // the carrier populations' β (the waiting correction's tables)
  std::vector<double> pair_radius_ = std::vector<double>(2), pair_beta_ = std::vector<double>(2),
                      pair_field_ = std::vector<double>(6), pair_p_ = std::vector<double>(6);
  void add_waiting_correction(std::size_t k, double s, const double x[3], double radius, double beta,
                              const double B[3], const double p[3], const double r[3], double F[3]);
  std::vector<std::int32_t> compact_origin_, new_index_;
  bool enabled_ = true;
  bool restored_ = false; // read_state() found state for these settings
  // The applied field's ramp factor s(t) when the held forces were evaluated.
  double held_ramp_ = 1.0;
  double last_scale_ = 1.0; // the ramp rescaling of the held forces at the last step

  void select_carriers(const dem::ParticleState &state);
  void admit_newcomers(const dem::ParticleState &state);
  void follow_engine_order();
  bool follow_engine_order_on_ = true;
  std::vector<std::int32_t> sort_order_; // follow_engine_order()'s permutation and scratch
  std::vector<double> sort_scratch_;
  std::vector<std::int32_t> sort_index_scratch_;
  std::vector<std::uint32_t> sort_carrier_scratch_;
  bool follow_exchange(const std::vector<std::int32_t> &origin);
  void defer_change(const std::vector<std::int32_t> &origin);
  bool admit_pending(const dem::ParticleState &state, double t);
  std::vector<std::uint32_t> leavers_; // admit_pending(): the carriers that left since the last one
  std::vector<std::uint32_t> still_waiting_; // admit_pending(): newcomers in empty fine cells
  std::vector<double> leaver_mu_r_, leaver_Ms_; // (their materials, should the admission fail)
  void add_waiting_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t);
  void add_waiting(dem::ForceBuffers &forces, std::uint32_t i, double fx, double fy, double fz);
  void apply_pending(const dem::ParticleState &state);
  BeadArrays bead_arrays() const;
  void gather_positions(const dem::ParticleState &state);
  // The held forces (scaled, plus the close pairs' changes `live` or none) added to `forces`.
  void add_held_forces(dem::ForceBuffers &forces, double scale, const std::vector<double> *live);
  const std::vector<double> *usable_live_changes(const std::vector<double> *live) const;
  // add_forces_in_team_if_held() found that this step must evaluate: its check, for add_forces().
  StalenessCheck team_check_;
  bool checked_in_team_ = false;
  bool held_steps_in_team_ = true;
  long steps_in_team_ = 0, steps_ = 0; // steps held inside the team, all steps (the log's note)
  // Quiet steps: the drift summed since the last check in the team, per thread (each keeps
  // the same value; own cache line), and whether that check found nothing stale.
  struct alignas(64) QuietMove
  {
    double moved = 0.0;
  };
  std::vector<QuietMove> quiet_moved_;
  bool quiet_valid_ = false, quiet_steps_on_ = true;
  // The size of the team whose threads all reset their sums at that check. The engine's team
  // changes size between its runs (one thread while the scene is small); a thread whose sum
  // was not reset then would decide otherwise than the others — a quiet step on one thread, a
  // check with barriers on the other: the team deadlocked (found in the regulation cell, 2
  // threads, at 1.3 ms). So the sums count only in a team of that size.
  int quiet_team_ = 0;
  long quiet_steps_ = 0, steps_in_team_waiting_ = 0;
  // The held forces of a step in the team; `checked`: its positions were gathered and checked
  // (otherwise a quiet step); `gathered`: the positions were gathered at this step. Newcomers
  // waiting for admission add their forces first.
  void add_held_step(const dem::ParticleState &state, dem::ForceBuffers &forces, double t, bool checked,
                     bool gathered);
  // Whether a step with newcomers waiting (pending_) would do nothing in add_forces() but add
  // their forces and the held ones: then it stays in the team (every thread decides alike).
  bool waiting_stays_in_team(const dem::ParticleState &state) const;
  AppliedFieldFunction lookup_at(double t) const;
  void full_refresh(const BeadArrays &beads, double t, double ramp);
  void take_held_forces();
};

} // namespace magbrush::magnetics
