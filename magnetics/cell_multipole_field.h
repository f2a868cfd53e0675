// The far field of point sources without a cutoff: a cell multipole method (a uniform
// octree of occupied cells, Cartesian Taylor expansions, periodic images to convergence).
// The sources are the induced magnetic dipoles (SourceKind::dipoles, the field B and its
// gradient) or charges, optionally with dipoles (SourceKind::charges: the potential
// Φ = Σ q/r, the field E = −∇Φ = Σ q r/r³ and its gradient, without the physical prefactor
// 1/(4πε0)); cartesian_taylor.h has the expansions of both. Periodic charges need no
// neutralising background: with one periodic axis the field of a row of charges converges
// (its potential diverges like a line charge's: it is regularised by dropping the same
// constant for every source, so Φ is exact up to a constant times the total charge); with two
// periodic axes a net charge per cell is a charged sheet in free space (field 2πσ on either
// side, potential −2πσ|h| far away, no constant dropped beyond the lattice regularisation).
//
// The beads are sorted into cubic-ish fine cells of size h (a few diameters). Pairs of beads
// in ADJACENT fine cells (|ΔI|∞ ≤ near_reach, periodic images included) are the near field:
// this class lists them (near_pairs()) and the caller treats them exactly (the magnetics in
// every sweep, with the `corrected` short range). Everything else — the whole domain, every
// periodic image — is the far field, evaluated like the classical fast multipole method:
//
//   1. P2M  every fine cell sums the Taylor moments of its sources about its centre;
//   2. M2M  moments move up the levels (cells of 2h, 4h, …; exact shifts);
//   3. M2L  at every level a cell receives, as a local Taylor expansion about its centre,
//           the field of the cells that are children of its parent's neighbours but not its
//           own neighbours (the classical interaction list, at most 189 cells); at the top
//           level (1 or 3 cells across each periodic axis, or a few cells when nothing is
//           periodic) it receives every non-adjacent top cell and all their periodic images,
//           through lattice-summed derivative tensors (1 periodic axis: ±400 images, error
//           ~1e-6; 2 periodic axes: images in a disc of radius 64 periods plus the analytic
//           continuum beyond it for the field and its gradient);
//   4. L2L  the local expansions move down to the fine cells;
//   5. L2P  every bead gets the far field and its gradient (and, for charges, the potential)
//           from its fine cell's expansion.
//
// Cost O(N) per evaluation (plus the one-time lattice sums of the top level, cached). The
// translation tensors depend only on the integer cell offset and are tabulated per level.
// Every loop writes only its own cell or bead, in a fixed order: the result is bit-identical
// for any number of threads.
#pragma once

#include "magnetics/cartesian_taylor.h"
#include "magnetics/magnetic_neighbour_list.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace magbrush::magnetics {

// Charge sources (SourceKind::charges): per bead a charge q (1 per bead) and/or a dipole p
// (3 per bead); a null pointer is no source of that kind. Units are the caller's.
struct FarFieldSources
{
  const double *charge = nullptr;
  const double *dipole = nullptr;
};

// What a charge far field returns per bead, OVERWRITTEN where the pointer is not null: the
// potential Φ (1 per bead), the field E = −∇Φ (3) and its gradient ∂_c E_a (9, 9b + 3a + c).
struct FarFieldTargets
{
  double *potential = nullptr;
  double *field = nullptr;
  double *gradient = nullptr;
};

class CellMultipoleField
{
public:
  // order: Taylor order p (cartesian_taylor.h); box[d] = periodic length (0 = open);
  // near_reach: the near field is the fine cells within ±near_reach (1: 27 cells, the
  // classical FMM; 2: 125 cells, which moves the nearest — strongest, for a 1/r³ kernel —
  // far interactions from a separation ratio of 0.87 to 0.58: far more accurate per order);
  // kind: dipoles (the magnetics) or charges (open, or periodic along one or two axes).
  CellMultipoleField(int order, const std::array<double, 3> &box, int near_reach = 2,
                     SourceKind kind = SourceKind::dipoles);

  // Sorts the beads into fine cells of target size `cell_size` [m] (periodic axes get k·2^m
  // cells exactly, k = 1 or 3), builds the levels, interaction lists and the near pair list.
  void build(std::size_t n, const double *x, const double *y, const double *z, double cell_size);
  // Only beads below `targets` need their near pairs (charges: the images of the pair images
  // are sources only); pairs of two beads ≥ targets are not listed. Before build(); default
  // all beads.
  void set_near_targets(std::size_t targets) { near_targets_ = targets; }

  // The beads moved (by less than a fraction of a cell since build()): keep the cells, the
  // lists and the near pairs (a bead stays in the cell it was sorted into, as in a Verlet
  // list), and take the new positions for the expansions. Positions are raw, as in build();
  // a bead wrapped by the caller since build() must trigger a build() instead.
  void update_positions(const double *x, const double *y, const double *z);

  // Beads appended since build() (indices bead_count() … n−1; x, y, z raw, all n beads) join
  // the fine cells they fall in, without a rebuild: the levels, interaction lists and
  // translations stay. Each must fall in an occupied fine cell (a new cell would change the
  // tree) and, along an open axis, not below the grid's origin (so that build() from the
  // same positions, as a restart does, finds the same cells and the same bead order). False,
  // and nothing changed, when some bead cannot join.
  bool add_beads(std::size_t n, const double *x, const double *y, const double *z);
  // Whether a bead at x (raw) could join: in an occupied fine cell, not below the origin.
  bool can_add(const double x[3]) const;
  // The near pairs of the beads appended from `first` on (with every bead, each pair once,
  // by the rule of build(): pairs with an older bead are listed from the older one), with
  // the image shifts for the raw positions given to build() / add_beads(). Appends to `out`.
  void appended_near_pairs(std::size_t first, std::vector<MagneticNeighbourList::Pair> &out) const;
  // Dipoles: the far field and gradient at bead b from its fine cell's local expansion of the
  // last evaluate() (L2P for one bead: what evaluate() gave the beads of that cell).
  void far_field_at(std::size_t b, double B[3], double gradB[9]) const;
  // The fine cells' local expansions of the last evaluate() (restart: with the cells rebuilt
  // from the same positions, set_fine_locals() restores them exactly).
  const std::vector<double> &fine_locals() const { return levels_.at(0).L; }
  bool set_fine_locals(const std::vector<double> &L);
  // The sources were scaled by `ratio` (a field ramp): so are the fine local expansions.
  void scale_fine_locals(double ratio)
  {
    if (!levels_.empty())
      for (double &v : levels_[0].L)
        v *= ratio;
  }
  std::size_t bead_count() const { return n_; }

  // Pairs of beads (and periodic images) in adjacent fine cells, each once, in a fixed order;
  // r = x_j − x_i + shift with the raw positions given to build().
  const std::vector<MagneticNeighbourList::Pair> &near_pairs() const { return near_pairs_; }
  // Hands the near pairs over without a copy: swaps them with `into`, whose (emptied) buffer
  // the next build() fills; near_pairs() is empty afterwards.
  void take_near_pairs(std::vector<MagneticNeighbourList::Pair> &into)
  {
    near_pairs_.swap(into);
    near_pairs_.clear();
  }

  // Dipoles: B_far [T] (3 per bead) and ∇B_far [T/m] (9 per bead, gradB[9b + 3a + c] =
  // ∂B_a/∂x_c) of the dipoles p (3 per bead, A m²), excluding the near pairs. Overwrites B
  // and gradB.
  void evaluate(const double *p, double *B, double *gradB);
  // Charges: the far potential, field and gradient of the sources, excluding the near pairs.
  void evaluate(const FarFieldSources &sources, const FarFieldTargets &targets);

  // M2L in single precision (default) or double (for the error table).
  void set_single_precision(bool single) { single_precision_ = single; }

  std::size_t fine_cells() const { return levels_.empty() ? 0 : levels_[0].keys.size(); }
  int levels() const { return static_cast<int>(levels_.size()); }
  std::size_t interactions() const; // M2L translations per evaluation
  const std::array<double, 3> &fine_cell_size() const { return h_; }

private:
  struct Level
  {
    std::array<double, 3> size;          // cell size per axis
    std::array<long, 3> cells;           // periodic axes: cell count (k·2^j); open: unused
    std::array<long, 3> factor{{1, 1, 1}}; // cells of this level per cell of the next, per axis
    std::vector<std::uint64_t> keys;     // occupied cells, sorted
    std::vector<std::array<long, 3>> index;
    std::vector<std::uint32_t> parent;   // index into the next level
    std::vector<std::uint32_t> child_begin, children; // CSR into the previous level
    std::vector<std::uint32_t> list_begin, list_source; // interaction list (CSR)
    std::vector<const double *> list_matrix;            // translation matrix per entry
    std::vector<const float *> list_matrix_f;           // the same in single precision
    std::vector<float> Mf;                              // moments in single precision (scaled)
    double scale = 1.0;                                 // length scale of the float numbers
    std::vector<double> row_scale;                      // s^(−|γ|−1) per local coefficient
    std::vector<double> M, L;            // moments and local coefficients per cell
    // Empty again, its vectors keeping their storage for the next build.
    void reset();
  };

  CartesianTaylor taylor_;
  std::array<double, 3> box_;
  std::array<double, 3> h_{0, 0, 0}, origin_{0, 0, 0};
  int near_reach_ = 2;
  int periodic_axes_ = 0;
  std::size_t n_ = 0;
  std::vector<Level> levels_;
  // The last build's levels, emptied, whose storage the next build takes over: a rebuild
  // allocates nothing once warm (freed and allocated afresh, the moments' arrays cost the
  // kernel's page zeroing, 5-8 % of a supplied development nip).
  std::vector<Level> spare_levels_;
  Level take_spare_level();
  std::vector<double> xw_;                 // wrapped positions (3 per bead)
  std::vector<double> wrap_shift_;         // xw − x at build() (multiples of the periods)
  std::vector<std::uint32_t> bead_order_;  // beads sorted by fine cell
  std::vector<std::uint32_t> bead_begin_;  // per fine cell, into bead_order_
  std::vector<std::uint32_t> bead_cell_;   // fine cell of every bead
  std::vector<MagneticNeighbourList::Pair> near_pairs_;
  MagneticNeighbourList::PairBlocks near_pair_blocks_; // build_near_pairs(): per-block buffers
  std::vector<std::uint32_t> order_scratch_, begin_scratch_; // add_beads()
  // Bead b's fine cell index vector from its wrapped position; false when it lies below the
  // origin along an open axis.
  bool fine_index(const double xw[3], std::array<long, 3> &I) const;
  std::vector<std::int32_t> neighbour_cell_, neighbour_image_; // build_near_pairs(): per fine cell
  std::size_t near_targets_ = static_cast<std::size_t>(-1);

  // Translation matrices A[γ][β] = D_(β+γ)(−Δ h_ℓ) for the 7³ offsets of every lower
  // level, and the lattice-summed ones of the upper levels per (level, offset, the level's
  // cell size): kept across rebuilds while h is unchanged (a lattice sum over a disc of
  // images costs more than a whole evaluation; the cell size of a level along an open axis
  // depends on how far the beads spread, so it is part of the key).
  using LatticeKey = std::array<long, 7>;
  LatticeKey lattice_key(int level, const std::array<long, 3> &offset) const;
  std::vector<std::vector<double>> offset_D_;
  std::map<LatticeKey, std::vector<double>> lattice_;
  std::vector<std::vector<float>> offset_Df_;
  std::map<LatticeKey, std::vector<float>> lattice_f_;
  bool single_precision_ = true;
  // build_interaction_lists(): the lattice-summed matrices of one level by offset D
  // (|D_d| ≤ memo_width / 2), so that each is looked up in the maps once per level.
  static constexpr long memo_width = 17;
  std::vector<std::pair<const double *, const float *>> lattice_memo_;
  int column_level_ = 0; // first level whose cells span the whole period (m + 1)
  std::array<double, 3> cached_h_{0, 0, 0};
  std::size_t cached_levels_ = 0;
  std::vector<std::array<double, 3>> cached_sizes_; // level cell sizes of offset_D_

  // Dense index of the occupied fine cells over their bounding box (−1 = empty), for O(1)
  // lookups while collecting the near pairs; empty when the box would be too large.
  std::vector<std::int32_t> dense_;
  std::array<long, 3> dense_extent_{0, 0, 0};
  void build_dense_index(const Level &fine);
  long find_fine(const std::array<long, 3> &I) const; // as find(levels_[0], I)

  std::uint64_t key_of(const std::array<long, 3> &I) const;
  long find(const Level &level, const std::array<long, 3> &I) const; // −1 if empty
  bool wrap(const Level &level, std::array<long, 3> &I) const;       // false if outside
  std::array<double, 3> centre(int level, const std::array<long, 3> &I) const;
  void build_levels();
  void build_interaction_lists();
  void build_near_pairs(const double *const coord[3]);
  bool near(int level, const std::array<long, 3> &D) const;
  const std::vector<double> &lattice_matrix(int level, const std::array<long, 3> &offset);
  // Charges with two periodic axes: the lattice sum by a smooth window and its continuum.
  void windowed_sheet_sum(int level, const std::array<long, 3> &offset, const int axes[2],
                          std::vector<double> &S);
  // The passes of an evaluation: P2M (add_sources(s, bead, M) adds a bead's moments at
  // offset s), M2M + M2L + L2L, and L2P (at_bead(u, bead, L) reads the cell's expansion).
  template <class AddSources> void form_multipoles(const AddSources &add_sources);
  void translate();
  template <class AtBead> void evaluate_at_beads(const AtBead &at_bead) const;
};

} // namespace magbrush::magnetics
