// Holding the dipoles instead of the forces between evaluations (MagneticSettings::
// hold_dipoles): the forces of the close pairs follow the beads.
//
// A held force goes stale mostly through the geometry of the close pairs — a touching pair's
// force goes as 1/r⁴, the two-sphere correction near contact more steeply still — while a
// dipole changes only through its neighbours' share of the local field. So between
// evaluations the close pairs' forces are evaluated every step at the current pair vectors
// from the HELD dipoles and local fields, and each bead gets
//
//     F_b = F_held,b + Σ_close pairs ± [ F_pair(p, B; r_now) − F_pair(p, B; r_base) ],
//
// where r_base is the pair vector at the moment the pair's stored force was last renewed (a
// full evaluation, or a local refresh or admission that renewed it). Everything else — the
// far field, the distant pairs, the applied field's gradient — stays held as before. The pair
// law is the solver's: the point-dipole pair force plus, for the `corrected` model, the exact
// two-sphere correction (TwoSphereCorrection::add), so at r_now = r_base the change is exactly
// zero. docs/magnetics.md ("Holding the dipoles instead of the forces") has the measurements.
//
// The changes are evaluated every MagneticSettings::live_pair_steps steps and held in between
// (a pair moves ~10⁻⁴ of a radius per step). Deterministic: every live pair writes its own slot, and each bead sums its pairs in a fixed
// order (the incidence built when the set changes), whatever the number of threads.
#pragma once

#include "common/state_stream.h"
#include "magnetics/bead_arrays.h"
#include "magnetics/near_pairs.h"
#include "magnetics/two_sphere_correction.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class LivePairs
{
public:
  // From now on the close near pairs: |r| < reach_factor × mean radius at their last tensor
  // evaluation (no skin: a pair that comes closer later stays held until the next selection),
  // not a bead's own image, both beads magnetised. Their base forces are set by rebase_all()
  // next.
  void select(const BeadArrays &beads, const NearPairs &near, double reach_factor);
  // Near pairs appended from `first_pair` on (an admission) join by the same rule; their base
  // forces are set by the rebase() of the admission's refresh.
  void append(const BeadArrays &beads, const NearPairs &near, std::size_t first_pair, double reach_factor);
  // The base forces at the current positions: of every live pair, or of the live ones among
  // the given near pairs (those whose stored force a local refresh renewed).
  void rebase_all(const InducedState &s, const TwoSphereCorrection *correction);
  void rebase(const InducedState &s, const TwoSphereCorrection *correction, const std::vector<std::uint32_t> &near_pairs);
  // Each bead's Σ ± (F_now − F_base) (3 per bead; forces only), evaluated at every
  // `steps`-th call since the last rebase and held in between (set_steps).
  const std::vector<double> &update(const InducedState &s, const TwoSphereCorrection *correction);
  // The same, called by EVERY thread of a team (the engine's, between its phases): the
  // passes are shared with `omp for`; the same bits as update().
  const std::vector<double> &update_in_team(const InducedState &s, const TwoSphereCorrection *correction);
  // The held state was scaled by the applied-field ratio (p, B ∝ ratio): base forces × ratio².
  void scale(double ratio2);
  void clear();
  void set_steps(int steps) { every_ = steps > 0 ? steps : 1; }
  std::size_t size() const { return pair_.size(); }
  // The next update() evaluates the changes (it reads the positions); otherwise it returns
  // the held ones.
  bool due() const { return calls_ % every_ == 0; }

  // Restart: the live pairs and their base forces (the incidence is rebuilt).
  void write_state(StateOut &out) const;
  void read_state(StateIn &in, std::size_t beads, const NearPairs &near);

private:
  std::vector<std::uint32_t> pair_;     // the near pair of each live pair
  // … and a copy of its beads and periodic shift, contiguous: the live pairs are a sparse
  // subset (a few per cent) of the near pairs, and reading them through the near list cost a
  // cache miss per pair, most of the updates' time (the near list never changes a pair in
  // place; it is forgotten, and the live pairs cleared, when the beads are re-sorted).
  std::vector<MagneticNeighbourList::Pair> ends_;
  std::vector<std::int32_t> live_of_;   // per near pair: its live index, or −1
  std::vector<double> base_, change_;   // 3 per live pair: force on j at r_base; F_now − F_base
  std::vector<double> bead_change_;     // 3 per bead: the changes held between evaluations
  int every_ = 1;                       // evaluate the changes at every every_-th call …
  long calls_ = 0;                      // … counted from the last rebase
  // Per bead, its live pairs as (index + 1) for the pair's j, −(index + 1) for its i, CSR.
  std::vector<std::uint32_t> start_;
  std::vector<std::int32_t> entry_;
  std::size_t beads_ = 0;

  void consider(const BeadArrays &beads, const NearPairs &near, std::size_t k, double reach_factor);
  // The changes at the current positions and each bead's sum: every thread of the current
  // team (or one outside a parallel region) shares the passes.
  void evaluate_changes(const InducedState &s, const TwoSphereCorrection *correction);
  void build_incidence();
  // The pair law at the current positions: the force on j of live pair m.
  void pair_force(const InducedState &s, const TwoSphereCorrection *correction, std::size_t m, double F[3]) const;
};

} // namespace magbrush::magnetics
