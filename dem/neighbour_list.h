// Verlet neighbour list on a cell grid, with the per-pair data that lives on it.
//
// * Half list: each pair (i, j), i < j in the current particle order, appears once, in CSR
//   rows by i. A transposed index (rows by j) lets a per-particle gather collect both sides
//   in a fixed order — that is what makes the forces bit-identical on any number of threads.
// * Verlet skin: pairs closer than r_i + r_j + skin are listed; the list stays valid until some
//   particle has moved more than skin/2 since the build (the engine checks that). With van
//   der Waals adhesion, which reaches a few nm beyond contact, the engine passes skin +
//   adhesion range here and keeps checking the drift against the skin alone.
// * Spatial sorting: every build first re-sorts the particles in cell order (a stable counting
//   sort), so neighbours are close in memory.
// * Contact history (the Mindlin ξ of each touching pair) is keyed by the particles' indices
//   at the last build while the list is rebuilt and mapped through the re-sorting (and
//   through a change of the particle set: particles that left or entered), so it survives
//   both; nothing here assumes that particle ids are dense.
// * Periodic directions use the minimum image; each pair stores which image it uses.
#pragma once

#include "dem/checkpoint_file.h"
#include "dem/particle_state.h"

#include <array>
#include <cstdint>
#include <vector>

namespace magbrush::dem {

// Periodic lengths along x, y, z (0 = not periodic). Periodic coordinates live in [0, L).
struct PeriodicBox
{
  std::array<double, 3> length{0.0, 0.0, 0.0};
  bool periodic(int d) const { return length[static_cast<std::size_t>(d)] > 0.0; }
  // Wraps the coordinates of every particle into [0, L) along periodic directions.
  void wrap(ParticleState &s) const;
};

class NeighbourList
{
public:
  // --- pair data, indexed by pair p -------------------------------------------------------
  std::vector<std::int32_t> row_start; // N + 1
  std::vector<std::int32_t> owner;     // i of pair p (the row it belongs to)
  std::vector<std::int32_t> partner;   // j of pair p
  std::vector<std::int32_t> image;     // periodic image code of j relative to i (see shift())
  std::vector<std::int32_t> touching;  // 1 while the pair overlaps
  std::vector<double> hist_x, hist_y, hist_z;                     // Mindlin ξ (on i)
  std::vector<double> force_x, force_y, force_z;                  // contact force on i
  std::vector<double> torque_j_x, torque_j_y, torque_j_z;         // torque on j (the torque on
                                                                  // i is summed by its row at once)
  // Transposed index: pairs in which particle k is the second member, ascending.
  std::vector<std::int32_t> col_start, col_pair;

  std::size_t pairs() const { return partner.size(); }
  // Shift to add to (x_j − x_i) for pair p.
  Vector3 shift(std::size_t p) const { return shifts_[image[p]]; }
  // The 27 image shifts, indexed by image code.
  const Vector3 *shifts() const { return shifts_.data(); }
  // One component (d = 0, 1, 2) of the 27 shifts, as an array (the pair kernel gathers them).
  const double *shift_component(int d) const { return shift_components_[static_cast<std::size_t>(d)].data(); }

  // Rebuilds the list. Before: keeps the touching pairs' history keyed by the particles'
  // indices at the last build; then re-sorts all particle arrays in cell order through
  // `permute` (a callback that applies an order to every per-particle array of the engine);
  // then builds the pairs and restores the history of every pair whose two particles were
  // both there at the last build.
  //
  // `origin` describes a change of the particle set since the last build (particles that
  // left, particles that entered): origin[k] = the index particle k had at the last build,
  // −1 for a particle that entered since; a particle whose index appears nowhere left, and
  // its contacts vanish with it. nullptr = the same particles in the same order.
  template <typename Permute>
  void rebuild(ParticleState &s, const PeriodicBox &box, double skin, Permute &&permute,
               const std::vector<std::int32_t> *origin = nullptr)
  {
    stash_history();
    box.wrap(s);
    compute_cell_order(s, box, skin);
    permute(order_);
    build_pairs(s, box, skin);
    restore_history(origin);
  }

  // Statistics of the last build.
  double cell_size() const { return cell_size_; }
  std::size_t memory_bytes() const;

  // The contact history in a checkpoint: the pairs (rows, partners), who touches, and ξ. The
  // rest is rebuilt at the first step after a restart.
  void write_history(CheckpointWriter &out) const;
  void read_history(CheckpointReader &in);

private:
  std::array<Vector3, 27> shifts_{};
  std::array<std::array<double, 27>, 3> shift_components_{};
  // Cell grid.
  std::array<double, 3> origin_{}, h_{};
  std::array<int, 3> n_{1, 1, 1};
  double cell_size_ = 0.0;
  std::vector<std::int32_t> cell_of_, cell_start_, order_, counts_;
  // Stashed history, CSR keyed by the particle index at the last build (partners likewise);
  // old_index_ maps the new order back to it.
  std::vector<std::int32_t> old_start_, old_partner_, old_index_;
  std::vector<double> old_hx_, old_hy_, old_hz_;

  void stash_history();
  void compute_cell_order(const ParticleState &s, const PeriodicBox &box, double skin);
  void build_pairs(const ParticleState &s, const PeriodicBox &box, double skin);
  void restore_history(const std::vector<std::int32_t> *origin);
};

} // namespace magbrush::dem
