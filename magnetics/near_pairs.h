// The near pairs: the bead pairs whose dipole coupling is treated exactly, in every
// Jacobi sweep — every pair within the cutoff (hard cutoff), or every pair of beads in
// neighbouring fine cells (cell-multipole far field, which supplies the rest).
//
// Per pair the pair vector r = x_j − x_i + shift, the dipole tensor T(r) (A11) and whether
// the pair interacts (within the cutoff, centres distinct) are evaluated once per
// evaluation in a parallel loop over pairs. A sweep then gathers, for every bead, the field
// Σ_k T_jk p_k of its partners: with the far field through per-bead rows (the partner and
// a copy of the tensor, contiguous per bead), so that a sweep streams through memory; with
// a hard cutoff through the neighbour list's incidence lists. Both visit the partners in
// the list's fixed incidence order, so every bead's sum is the same on any number of
// threads.
#pragma once

#include "common/state_stream.h"

#include "magnetics/bead_arrays.h"
#include "magnetics/dipole_physics.h"
#include "magnetics/magnetic_neighbour_list.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class NearPairs
{
public:
  MagneticNeighbourList &list() { return list_; }
  const MagneticNeighbourList &list() const { return list_; }
  const std::vector<MagneticNeighbourList::Pair> &pairs() const { return list_.pairs(); }

  // Every pair's vector, tensor and interaction flag at the current positions; returns the
  // number of interacting pairs. Pairs at or beyond `cutoff` do not interact.
  std::size_t evaluate_tensors(const BeadArrays &beads, double cutoff);
  // Pair k's vector, tensor and flag again (a local refresh; the cutoff of the last
  // evaluate_tensors()), and its copies in the two beads' rows when they exist.
  void evaluate_tensor(const BeadArrays &beads, std::size_t k);
  void update_rows(std::size_t k);

  // Beads and pairs were appended to the list (MagneticNeighbourList::append): the tensors
  // of the pairs from `first_pair` on are evaluated; the rows are out of date from then on.
  void appended(const BeadArrays &beads, std::size_t first_pair);

  // Builds the per-bead rows from the tensors (the sweeps of the cell-multipole path), and
  // whether they are there and current (built for every pair of the list).
  void build_rows();
  bool has_rows() const { return !row_entry_.empty() && row_entry_.size() == 2 * list_.pairs().size(); }

  bool active(std::size_t k) const { return active_[k]; }
  const double *r(std::size_t k) const { return &r_[3 * k]; }
  const DipoleTensor &tensor(std::size_t k) const { return tensor_[k]; }

  // The partners' field at bead b, Σ_k T_bk p_k: through the rows, ADDED to s (which the
  // caller starts from the far field); through the list, ADDED to B.
  void add_row_field(std::size_t b, const std::vector<double> &p, double s[3]) const;
  // The same sum, bit for bit, read through the list's incidence and the tensors (the rows
  // out of date: beads admitted since the last full evaluation).
  void add_row_field_through_list(std::size_t b, const std::vector<double> &p, double s[3]) const;
  void add_list_field(std::size_t b, const std::vector<double> &p, double B[3]) const;

  // Forget the pairs (the caller re-sorted its beads: pair indices refer to the old order);
  // the buffers are kept for the next build.
  void forget() { list_.clear(); }

  // Restart (common/state_stream.h): the list, the tensors and flags; the rows are rebuilt
  // from the tensors (copies of them).
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  MagneticNeighbourList list_;
  double cutoff_ = 0.0;
  std::vector<DipoleTensor> tensor_;
  std::vector<double> r_;
  std::vector<unsigned char> active_;
  // Rows: the other bead and a copy of the pair tensor (6 per entry), CSR in row_begin_ (the
  // list's incidence packed); row_entry_[2k + side] = the entry of pair k in its i row
  // (side 0) and j row (side 1).
  std::vector<std::size_t> row_begin_;
  std::vector<std::uint32_t> row_other_;
  std::vector<double> row_tensor_;
  std::vector<std::size_t> row_entry_;
};

} // namespace magbrush::magnetics
