// Induced magnetic dipoles of carrier beads with mutual induction, and the forces they feel
// (Kawamoto A8–A11, Kweon eq. 2–5), on structure-of-arrays inputs.
//
// One evaluation (InducedDipoles::compute) runs like the algorithm:
//   1. refresh the magnetic neighbour list if a bead moved more than half the skin;
//   2. applied field B0 and its gradient at every bead (the caller's field);
//   3. dipole tensors T of every pair within the cutoff;
//   4. dipoles: point_dipole  p_j = α_j B0_j (one pass);
//               mutual_dipole p_j = α_j (B0_j + Σ_k T_jk p_k), Jacobi sweeps from the previous
//               dipoles until max|Δp| ≤ tolerance·max|p| (saturating beads use the
//               Fröhlich–Kennelly law in place of α_j);
//   5. pair forces F_dd(k → j), each pair once, stored and applied ±(Newton's third law holds
//      exactly); `corrected` adds, below a few radii, the exact-minus-mutual two-sphere force
//      in the local field of the pair;
//   6. per bead: F_j = (p_j·∇)B0_j + Σ ± pair forces, gathered in a fixed order.
// Every parallel loop writes only its own entries and sums in a fixed order, so the result is
// bit-identical for any number of OpenMP threads. Between neighbour-list rebuilds no memory
// is allocated (a rebuild uses temporary cell arrays; a new β builds its table once).
//
// The DEM may hold the magnetic forces between evaluations: check_staleness() says when and
// why they are stale (interval elapsed; beads or close pairs moved past a fraction of a radius,
// by the StalenessMode), refresh_locally() renews them around what moved (holding the far
// field and everyone else's dipoles), compute() renews everything, and add_held_forces() adds
// the forces of the last evaluation.
#pragma once

#include "cell_multipole_field.h"
#include "dipole_physics.h"
#include "magnetic_neighbour_list.h"
#include "magnetic_settings.h"
#include "two_sphere_table.h"

#include <array>
#include <cstdint>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <vector>

namespace magbrush::magnetics {

// The applied field: B [T] and its gradient gradB[a][b] = ∂B_a/∂x_b [T/m] at a point [m].
// Called concurrently from several threads: it must be thread-safe (read-only).
using AppliedFieldFunction =
  std::function<void(const double x[3], double B[3], double gradB[3][3])>;

// A uniform applied field (no gradient): the compression test and the verification tests.
AppliedFieldFunction uniform_field(double Bx, double By, double Bz);

// The carrier beads (structure of arrays, n entries each; SI units).
struct BeadArrays
{
  std::size_t n = 0;
  const double *x = nullptr, *y = nullptr, *z = nullptr;
  const double *radius = nullptr;
  const double *mu_r = nullptr;                     // relative permeability per bead
  const double *saturation_magnetisation = nullptr; // M_s [A/m] per bead; null or 0 = linear
};

// Where the forces (and optionally torques) are ADDED. Torque pointers may be null.
struct ForceArrays
{
  double *fx = nullptr, *fy = nullptr, *fz = nullptr;
  double *tx = nullptr, *ty = nullptr, *tz = nullptr;
};

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

// Why a refresh is due (InducedDipoles::check_staleness).
enum class RefreshReason { none, first, bead_count, interval, moved };

struct StalenessCheck
{
  RefreshReason reason = RefreshReason::none;
  std::size_t stale_beads = 0; // beads past the staleness limit
  std::size_t stale_pairs = 0; // relative mode: watched pairs past it
  double max_move = 0.0;       // largest displacement since the bead's last evaluation / radius
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

  // True when the held forces are stale: never computed, bead count changed, the refresh
  // interval has elapsed since the last compute(), or some bead moved more than
  // staleness_fraction × its radius since its force was evaluated (minimum image: a
  // periodic wrap is no move). check_staleness() says which, and how many beads moved.
  bool needs_refresh(const BeadArrays &beads, double time) const;
  StalenessCheck check_staleness(const BeadArrays &beads, double time) const;

  // Adds the forces (and torques) of the last compute() / refresh_locally() again.
  void add_held_forces(const ForceArrays &out) const;

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

  const MagneticSettings &settings() const { return settings_; }
  // relative: the pairs whose relative displacement is watched.
  std::size_t watched_pairs() const { return close_.size(); }
  const MagneticNeighbourList &neighbour_list() const { return list_; }
  // Dipoles [A m²] and local fields B_j [T] (applied + other dipoles) of the last compute,
  // interleaved (x, y, z) per bead.
  const std::vector<double> &dipoles() const { return p_; }
  const std::vector<double> &local_fields() const { return B_local_; }
  // The far field [T] of the last compute (3 per bead; empty without cell_multipole).
  const std::vector<double> &far_fields() const { return B_far_; }

private:
  MagneticSettings settings_;
  std::array<double, 3> box_;
  MagneticNeighbourList list_;

  // Per bead (interleaved x, y, z; gradients 9 per bead).
  std::vector<double> beta_, Ms_, B0_, gradB0_, p_, p_next_, B_local_, force_, torque_;
  std::vector<double> x_last_; // per bead: position at its last force evaluation (staleness)
  double t_last_ = 0.0;         // time of the last full compute()
  bool zero_field_ = false;     // the last compute() found no applied field at any bead
  double cutoff_ = 0.0;         // pair cutoff of the last compute (∞ with the far field)
  double skin_ = 0.0;           // Verlet skin of the last compute [m]
  bool computed_ = false;

  // Per pair within the list: dipole tensor, pair vector, active flag, force on the j bead.
  std::vector<DipoleTensor> tensor_;
  std::vector<double> r_;
  std::vector<unsigned char> active_;
  std::vector<double> pair_force_;

  // Slab tail correction (settings.slab_tail_correction): beads sorted along the open axis,
  // their cutoff windows in that order, prefix sums of the sheet moments, and the tail
  // field and its derivative along the open axis per bead.
  int normal_axis_ = -1;
  double tail_area_ = 0.0, tail_cutoff_ = 0.0;
  std::vector<std::uint32_t> tail_order_;
  std::vector<std::size_t> tail_lo_, tail_hi_;
  std::vector<double> tail_u_, tail_S0_, tail_S1_, tail_S2_, tail_B_, tail_dB_;

  // `corrected`: one table per distinct pair β (mean of the two beads' β).
  std::map<double, std::shared_ptr<const TwoSphereTable>> tables_;
  std::vector<const TwoSphereTable *> pair_table_;

  // Cell-multipole far field: the near list (list_) holds the pairs in neighbouring fine
  // cells, rebuilt at every compute; the far field and its gradient per bead; the
  // `corrected` pairs (within switch_end, which may lie in non-neighbouring cells) come
  // from their own short Verlet list, with their correction forces.
  std::unique_ptr<CellMultipoleField> far_;
  std::vector<double> B_far_, gradB_far_;
  // Per-bead neighbour entries of the near field for the sweeps (cell_multipole): the other
  // bead and the pair tensor, contiguous per bead (CSR in near_begin_), so that a sweep
  // streams through memory instead of chasing pair indices.
  std::vector<std::size_t> near_begin_;
  std::vector<std::uint32_t> near_other_;
  std::vector<double> near_tensor_; // 6 per entry
  MagneticNeighbourList correction_list_;
  std::vector<double> correction_force_;
  // Both incidence entries (i side, j side) of every near pair: a local refresh updates the
  // per-bead tensor copies of a pair it recomputes.
  std::vector<std::size_t> pair_entry_;

  // Local refresh work space: marks per bead / pair (cleared after use) and index lists.
  std::vector<std::uint8_t> bead_mark_, pair_mark_, correction_mark_;
  std::vector<std::uint32_t> moved_, region_, changed_, gathered_, touched_pairs_;
  std::vector<double> region_p_; // the region's dipoles before the local sweeps
  // relative: the pairs whose relative displacement is watched, compact for the per-step
  // check: drift = x_j − x_i + c, c = image shift − pair vector at the tensor's evaluation;
  // stale when |drift|² > limit2 = (staleness_fraction × mean radius)². close_of_pair_[k] =
  // the record of list pair k (−1 = not watched).
  struct ClosePair
  {
    std::uint32_t i, j;
    double c[3];
    double limit2;
  };
  std::vector<ClosePair> close_;
  std::vector<std::int32_t> close_of_pair_;
  double min_radius_ = 0.0, max_radius_ = 0.0;
  mutable std::vector<double> move2_; // per-step scratch of check_staleness: |Δx_b|²
  std::vector<double> limit2_, inv_radius2_; // per bead: move_limit², 1/radius²

  double cutoff_length(const BeadArrays &beads) const;
  void refresh_list_if_needed(const BeadArrays &beads, double cutoff, MagneticStats &stats);
  void evaluate_applied_field(const BeadArrays &beads, const AppliedFieldFunction &field);
  void evaluate_applied_field_at(const BeadArrays &beads, const AppliedFieldFunction &field, std::size_t b);
  void evaluate_pair_tensors(const BeadArrays &beads, double cutoff, MagneticStats &stats);
  void build_near_entries();
  void prepare_tail(const BeadArrays &beads, double cutoff);
  void evaluate_tail(const std::vector<double> &p);
  void gather_local_field(std::size_t b, const std::vector<double> &p, double B[3]) const;
  void solve_dipoles(const BeadArrays &beads, MagneticStats &stats);
  // Jacobi sweeps over all beads, or over `subset` only (the others' dipoles held).
  void sweep_to_tolerance(const BeadArrays &beads, MagneticStats &stats,
                          const std::vector<std::uint32_t> *subset = nullptr);
  // Pair k's vector, tensor and active flag at the current positions.
  void evaluate_pair_tensor(const BeadArrays &beads, std::size_t k);
  // Pair k's force on its j bead (dipole–dipole, plus the correction with a hard cutoff).
  bool evaluate_pair_force(const BeadArrays &beads, std::size_t k, const TwoSphereTable *single);
  bool evaluate_correction_force(const BeadArrays &beads, std::size_t k, const TwoSphereTable *single);
  // Bead b's total force and torque from the stored pair forces, in the fixed order.
  void gather_bead(std::size_t b);
  void store_reference_position(const BeadArrays &beads, std::size_t b);
  void store_limits(const BeadArrays &beads); // limit2_, inv_radius2_ of the beads
  // |x_b − x_last,b|² (minimum image along periodic axes).
  double squared_move(const BeadArrays &beads, std::size_t b) const;
  // Bead b's staleness limit on its absolute move [m]: staleness_fraction × radius, times
  // absolute_factor in the relative mode.
  double move_limit(const BeadArrays &beads, std::size_t b) const;
  // relative: |Δr|² of a watched pair since its tensor was evaluated [m²].
  static double drift2(const BeadArrays &beads, const ClosePair &c)
  {
    const double d[3] = {beads.x[c.j] - beads.x[c.i] + c.c[0], beads.y[c.j] - beads.y[c.i] + c.c[1],
                         beads.z[c.j] - beads.z[c.i] + c.c[2]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  }
  void select_close_pairs(const BeadArrays &beads);
  void update_close_pair(std::size_t k); // after pair k's tensor was re-evaluated
  void refresh_correction_list(const BeadArrays &beads);
  void evaluate_correction_forces(const BeadArrays &beads, MagneticStats &stats);
  // Adds the exact-minus-mutual two-sphere force of pair (i, j), r = x_j − x_i, to F (the
  // force on j); false when the pair is beyond switch_end.
  bool add_correction(const BeadArrays &beads, std::uint32_t i, std::uint32_t j,
                      const double r[3], const DipoleTensor &T, const TwoSphereTable *single,
                      double F[3]) const;
  void prepare_correction_tables();
  void evaluate_pair_forces(const BeadArrays &beads, MagneticStats &stats);
  void gather_forces(const ForceArrays &out);
};

} // namespace magbrush::magnetics
