// Induced magnetic dipoles of carrier beads with mutual induction, and the forces they feel
// (Kawamoto A8–A11, Kweon eq. 2–5), on structure-of-arrays inputs.
//
// InducedDipoles orchestrates one evaluation (compute) like the algorithm:
//   1. setup:          β (and saturation) per bead;
//   2. applied field:  B0 and its gradient at every bead (the caller's field); none at any
//                      bead means no dipoles and no forces;
//   3. near pairs:     the pairs treated exactly (near_pairs.h) — within the cutoff (a Verlet
//                      list), or in neighbouring fine cells of the far field — and their
//                      dipole tensors; with a hard cutoff in a slab, the tail beyond it
//                      (slab_tail.h);
//   4. far field:      everything else, every periodic image, by cell multipoles
//                      (cell_multipole_field.h), from the dipoles at the start of the solve;
//   5. sweeps:         point_dipole  p_j = α_j B0_j (one pass);
//                      mutual_dipole p_j = α_j (B0_j + Σ_k T_jk p_k + far + tail), Jacobi
//                      sweeps from the previous dipoles to the tolerance (jacobi_solver.h);
//   6. forces:         the pair forces, each pair once, stored and applied ± (pair_forces.h),
//                      with the `corrected` short range (two_sphere_correction.h); per bead
//                      F_j = (p_j·∇)(B0 + B_far)_j + tail + Σ ± pair forces, in a fixed order.
// Every parallel loop writes only its own entries and sums in a fixed order, so the result is
// bit-identical for any number of OpenMP threads. Between neighbour-list rebuilds no memory
// is allocated; a rebuild refills the pair, incidence and row buffers of the last one (only
// per-bead and per-cell temporaries are allocated; a new β builds its table once).
//
// The DEM may hold the magnetic forces between evaluations: check_staleness() says when and
// why they are stale (staleness_tracker.h), refresh_locally() renews them around what moved
// (local_refresh.h: holding the far field and everyone else's dipoles), compute() renews
// everything, and add_held_forces() adds the forces of the last evaluation.
#pragma once

#include "common/state_stream.h"

#include "magnetics/bead_arrays.h"
#include "magnetics/cell_multipole_field.h"
#include "magnetics/jacobi_solver.h"
#include "magnetics/live_pairs.h"
#include "magnetics/local_refresh.h"
#include "magnetics/magnetic_neighbour_list.h"
#include "magnetics/magnetic_settings.h"
#include "magnetics/near_pairs.h"
#include "magnetics/pair_forces.h"
#include "magnetics/slab_tail.h"
#include "magnetics/staleness_tracker.h"
#include "magnetics/two_sphere_correction.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace magbrush::magnetics {

struct MagneticStats
{
  int sweeps = 0;               // field gathers (mutual induction sweeps); 0 for point_dipole
  double relaxation = 1.0;      // final under-relaxation factor ω (1 = plain Jacobi)
  double residual = 0.0;        // max|Δp| / max|p| of the last sweep
  bool converged = true;        // residual ≤ tolerance within max_sweeps
  std::size_t pairs = 0;        // pairs (incl. periodic images) within the cutoff
  std::size_t listed_pairs = 0; // pairs in the neighbour list (cutoff + skin)
  std::size_t corrected_pairs = 0; // pairs that received the exact two-sphere correction
  bool list_rebuilt = false;
  double cutoff = 0.0;          // cutoff length used [m] (0 with the cell-multipole far field)
  int far_passes = 0;           // far-field evaluations (cell_multipole)
  std::size_t far_cells = 0;    // occupied fine cells
  std::size_t far_interactions = 0; // M2L translations per far-field evaluation
  // Wall time of the phases [s]: neighbour lists / cells, applied field + pair tensors,
  // far field, sweeps (near field), pair forces + gather.
  double time_lists = 0, time_tensors = 0, time_far = 0, time_sweeps = 0, time_forces = 0;
  // The applied field was zero at every bead: no dipoles, no forces, nothing solved.
  bool zero_field = false;
  // refresh_locally(): beads that moved past the staleness limit, the region whose dipoles
  // were solved again (those and their near neighbours), pairs whose force was recomputed,
  // beads whose force was gathered again. All 0 after a full compute().
  std::size_t local_moved = 0, local_region = 0, local_pairs = 0, local_gathered = 0;
};

class InducedDipoles
{
public:
  // box[d] = periodic length along axis d [m] (0 = not periodic).
  explicit InducedDipoles(const MagneticSettings &settings,
                          const std::array<double, 3> &box = {0.0, 0.0, 0.0});

  // Solves for the dipoles at time `time` and ADDS the magnetic forces (and torques, if the
  // settings ask for them) to `out`. The dipoles are kept as the next initial guess.
  MagneticStats compute(const BeadArrays &beads, const AppliedFieldFunction &field,
                        double time, const ForceArrays &out);

  // The forces of the given dipoles `p` (3 per bead, this call's bead order) at the beads'
  // current positions, without solving for the dipoles: the applied field and its gradient,
  // the near pairs' tensors, the far field and the local fields from `p`, then the forces as
  // compute() takes them. What a scheme that holds the dipoles between evaluations but moves
  // the beads would feel (bench_magnetic_staleness measures its error against a fresh solve).
  // The dipoles are kept as the next compute()'s start.
  MagneticStats forces_of_dipoles(const BeadArrays &beads, const AppliedFieldFunction &field, double time,
                                  const std::vector<double> &p, const ForceArrays &out);

  // True when the held forces are stale: never computed, bead count changed, the refresh
  // interval has elapsed since the last compute(), or some bead moved more than
  // staleness_fraction × its radius since its force was evaluated (minimum image: a
  // periodic wrap is no move). check_staleness() says which, and how many beads moved.
  // check_staleness() may be called by every thread of a team (its passes are shared, all
  // get the verdict) or by one thread outside a parallel region.
  bool needs_refresh(const BeadArrays &beads, double time) const;
  StalenessCheck check_staleness(const BeadArrays &beads, double time) const;

  // Adds the forces (and torques) of the last compute() / refresh_locally() again.
  void add_held_forces(const ForceArrays &out) const;
  // MagneticSettings::hold_dipoles: per bead (3 each), how the forces of its close pairs
  // changed since they were last evaluated, at the beads' current positions with the held
  // dipoles (live_pairs.h); null when nothing is live. `beads` = the held state's beads.
  // Call once per step: the changes are evaluated every live_pair_steps calls.
  const std::vector<double> *live_pair_changes(const BeadArrays &beads);
  // The same, called by every thread of a team (the passes shared with `omp for`).
  const std::vector<double> *live_pair_changes_in_team(const BeadArrays &beads);
  // The same, added to `out` (tests).
  void add_live_pair_changes(const BeadArrays &beads, const ForceArrays &out);
  std::size_t live_pairs() const { return live_.size(); }
  // The next live_pair_changes() reads the beads' positions (otherwise it returns the held
  // changes without looking at them).
  bool live_pair_changes_due() const { return live_.due(); }

  // After a check_staleness() whose verdict was "none": how far every bead may move from
  // where it saw them before a check could say anything else, the interval aside [m]
  // (StalenessTracker::quiet_distance); and whether the refresh interval has elapsed.
  double quiet_distance() const { return staleness_.quiet_distance(); }
  bool interval_due(double time) const { return staleness_.interval_due(time); }

  // The local refresh (StalenessMode::local): re-evaluates the magnetics around the beads
  // that moved more than staleness_fraction × their radius since their forces were last
  // evaluated, holding everything else:
  //   1. the moved beads' applied field and the tensors of their near pairs;
  //   2. the dipoles of the region R = moved beads + their near neighbours, Jacobi sweeps to
  //      the tolerance with the dipoles outside R and the far field held;
  //   3. the force of every pair touching R (stored once per pair and applied ±: Newton's
  //      third law stays exact), `corrected` pairs included, and the far-field force of R;
  //   4. the total force of every bead touching those pairs, gathered in the fixed order.
  // The refresh interval still counts from the last full compute(). Returns false and
  // changes nothing when a local refresh cannot stand in for a full one: nothing computed
  // yet, the bead count changed, a neighbour list expired (a bead moved half the skin or was
  // wrapped), the slab tail is on, or R would exceed local_region_limit of the beads; the
  // caller then calls compute(). With no moved bead it does nothing and returns true.
  bool refresh_locally(const BeadArrays &beads, const AppliedFieldFunction &field, double time,
                       MagneticStats &stats);
  // Why the last refresh_locally() returned false (a full evaluation is due): the lists
  // expired (a bead moved half the skin; or no local version: slab tail, nothing held), or
  // the region grew past local_region_limit of the beads. For the profile of what fires the
  // full evaluations.
  enum class LocalFallback { none, lists, region };
  LocalFallback local_fallback() const { return local_fallback_; }

  // Linear beads only (no saturation): the applied field was scaled by `ratio` (a ramp):
  // scales the held dipoles, fields and forces accordingly (p ∝ B, F ∝ B²: exact), so that a
  // local refresh continues from a consistent state. Throws for saturating beads.
  void scale_applied_field(double ratio);
  // True when every bead of the last compute() is linear (no saturation magnetisation).
  bool linear() const;

  // Forget the dipoles (the next compute starts from the applied-field dipoles).
  void reset_dipoles() { p_.clear(); }

  // The caller re-sorted its beads (new[k] = old[order[k]]): the kept dipoles, held forces
  // and reference positions follow, and the neighbour list is rebuilt at the next compute.
  void particles_reordered(const std::vector<std::int32_t> &order);
  // The caller's bead set changed (beads left, beads entered): new[k] = old[origin[k]],
  // origin[k] = −1 for a bead that entered. The kept beads keep their dipoles as the next
  // compute()'s initial guess, the new ones start from their applied-field dipole (with the
  // cold start's extra far-field pass); everything else is rebuilt by that compute(), which
  // must be the next call.
  void particles_changed(const std::vector<std::int32_t> &origin);

  // An exchange admitted without a rebuild (MagneticSettings::admit_exchange). `beads`: the
  // beads of the held state (indices < first, same order) followed by the newcomers (first …
  // n−1). `leavers` (ascending, < first): beads whose particle left; from now on they are
  // inert holes — the caller passes them with μr = 1 and no saturation (β = 0: no dipole, no
  // force, no two-sphere correction) at their last position — until a rebuild drops them
  // (particles_changed). The newcomers join the kept fine cells (CellMultipoleField::
  // add_beads), the near pairs, the correction's list and the watched pairs; their far field
  // is the held one (their fine cell's local expansion of the last evaluation); then a local
  // refresh around the newcomers and the leavers solves the dipoles of the region (the newcomers and everything within local_region_radius of
  // them or of a leaver) and renews the forces of every pair touching a changed dipole, as
  // refresh_locally() does. What is held (the far field of everything else) stays held until
  // the next compute(). Returns false and changes nothing when this cannot be done: no
  // cell-multipole far field, the point-dipole model, nothing held (as for a local refresh),
  // lists expired, a newcomer outside the occupied fine cells or larger than the correction's
  // list allows, or of a β without a correction table.
  bool admit(const BeadArrays &beads, std::size_t first, const std::vector<std::uint32_t> &leavers,
             const AppliedFieldFunction &field, MagneticStats &stats);
  // The near lists (and the correction's) still hold these beads and no bead moved half the
  // skin: the next compute() keeps them (no rebuild).
  bool lists_current(const BeadArrays &beads) const;
  // Whether a newcomer at x (raw) could be admitted as far as the far field's cells go (an
  // occupied fine cell); the caller keeps the others waiting.
  bool admissible_position(const double x[3]) const { return far_ && far_->can_add(x); }

  // Restart (common/state_stream.h): everything a later evaluation or local refresh reads —
  // the held forces, the dipoles (the next solve's start), the fields, the near pairs and
  // their stored forces, the staleness references — so that a restarted run continues bit
  // for bit. The far field's cells are rebuilt from the near list's reference positions
  // (the positions they were built from: the same cells). The state opens with the
  // settings; read_state() returns false and restores nothing when they differ from these
  // (the next evaluation then starts afresh).
  void write_state(StateOut &out) const;
  bool read_state(StateIn &in);

  const MagneticSettings &settings() const { return settings_; }
  // relative: the pairs whose relative displacement is watched.
  std::size_t watched_pairs() const { return staleness_.close_pairs().size(); }
  const MagneticNeighbourList &neighbour_list() const { return near_.list(); }
  // Dipoles [A m²] and local fields B_j [T] (applied + other dipoles) of the last compute,
  // interleaved (x, y, z) per bead.
  const std::vector<double> &dipoles() const { return p_; }
  const std::vector<double> &local_fields() const { return B_local_; }
  // The far field [T] of the last compute (3 per bead; empty without cell_multipole).
  const std::vector<double> &far_fields() const { return B_far_; }

private:
  MagneticSettings settings_;
  std::array<double, 3> box_;

  // The collaborators, in the order of the algorithm.
  NearPairs near_;                          // exact pairs and their tensors
  std::unique_ptr<SlabTail> tail_;          // hard cutoff in a slab: the field beyond it
  std::unique_ptr<CellMultipoleField> far_; // no cutoff: the field of everything else
  JacobiSolver solver_;                     // the mutual induction
  PairForces pair_forces_;                  // stored near-pair forces
  TwoSphereCorrection correction_;          // `corrected`: the exact two-sphere short range
  StalenessTracker staleness_;              // when the held forces go stale
  LocalRefresh local_;                      // what a local refresh re-evaluates
  LivePairs live_;                          // hold_dipoles: the close pairs' forces follow the beads

  // Per bead (interleaved x, y, z; gradients 9 per bead): β, saturation magnetisation,
  // applied field and gradient, dipoles (and the sweeps' next dipoles), local field, far
  // field and gradient, and the held force and torque.
  std::vector<double> beta_, Ms_, B0_, gradB0_, p_, p_next_, B_local_, B_far_, gradB_far_;
  std::vector<double> force_, torque_;
  std::vector<MagneticNeighbourList::Pair> spare_pairs_; // an empty pair buffer (update_cells)
  std::vector<std::uint32_t> fresh_; // beads that entered since the last compute (particles_changed)
  std::vector<MagneticNeighbourList::Pair> admitted_pairs_; // admit(): the newcomers' near pairs
  std::vector<std::uint32_t> admitted_moved_;                // admit(): newcomers and leavers
  bool computed_ = false;
  LocalFallback local_fallback_ = LocalFallback::none;
  bool zero_field_ = false; // the last compute() found no applied field at any bead
  double skin_ = 0.0;       // Verlet skin of the last compute [m]
  double far_cell_size_ = 0.0; // fine cell size of the last far-field build [m]

  // compute(), step by step.
  void set_materials(const BeadArrays &beads);
  void evaluate_applied_field(const BeadArrays &beads, const AppliedFieldFunction &field);
  void evaluate_applied_field_at(const BeadArrays &beads, const AppliedFieldFunction &field, std::size_t b);
  void hold_zero_forces(const BeadArrays &beads, double time);
  double find_near_pairs(const BeadArrays &beads, MagneticStats &stats); // returns the cutoff
  void update_cells(const BeadArrays &beads, double radius_sum, MagneticStats &stats);
  void update_cutoff_list(const BeadArrays &beads, double cutoff, MagneticStats &stats);
  double cutoff_length(const BeadArrays &beads) const;
  void evaluate_pair_tensors(const BeadArrays &beads, double cutoff, MagneticStats &stats);
  void solve_dipoles(const BeadArrays &beads, MagneticStats &stats);
  void evaluate_far_field(MagneticStats &stats);
  void hold_point_dipoles();
  // Jacobi sweeps over all beads, or over `subset` only (the others' dipoles held).
  void sweep_to_tolerance(const BeadArrays &beads, MagneticStats &stats,
                          const std::vector<std::uint32_t> *subset = nullptr);
  // Bead b's local field from the dipoles p: applied + tail + far + near pairs.
  void gather_local_field(std::size_t b, const std::vector<double> &p, double B[3]) const;
  void evaluate_forces(const BeadArrays &beads, MagneticStats &stats);
  void hold_forces_of_dipoles(const BeadArrays &beads, double time, MagneticStats &stats, const ForceArrays &out);
  const TwoSphereCorrection *near_pair_correction() const; // with a hard cutoff only
  bool far_corrections() const; // `corrected` with the far field: the correction's own list
  void gather_forces(const ForceArrays &out);
  // Bead b's total force and torque from its dipole, the fields and the stored pair forces.
  void gather_bead(std::size_t b);
  void remember_evaluation(const BeadArrays &beads, double time);
  // hold_dipoles: the correction the live pairs apply (the `corrected` model's), or null.
  const TwoSphereCorrection *live_correction() const;
  bool live_pairs_held(const BeadArrays &beads) const; // hold_dipoles, with live pairs for these beads

  // admit(), step by step.
  bool can_admit(const BeadArrays &beads, std::size_t first) const;
  void append_bead_state(const BeadArrays &beads, std::size_t first, const std::vector<std::uint32_t> &leavers,
                         const AppliedFieldFunction &field);
  void solve_around(const BeadArrays &beads, std::size_t first, const std::vector<std::uint32_t> &leavers,
                    const AppliedFieldFunction &field, MagneticStats &stats);

  // refresh_locally(), step by step.
  bool can_refresh_locally(const BeadArrays &beads) const;
  void reevaluate_moved_beads(const BeadArrays &beads, const AppliedFieldFunction &field);
  void reevaluate_local_forces(const BeadArrays &beads, MagneticStats &stats);
  void solve_region_and_refresh_forces(const BeadArrays &beads, MagneticStats &stats);
};

} // namespace magbrush::magnetics
