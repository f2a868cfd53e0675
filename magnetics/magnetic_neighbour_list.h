// The magnetic neighbour list: every unordered pair of beads (and every periodic image of a
// pair) closer than the list radius (cutoff + skin), each exactly once. It is separate from
// the contact list because its radius is many diameters, not one.
//
// Periodic boxes: a box length of 0 means "not periodic" along that axis. The cutoff may
// exceed half the box (even the whole box): a bead then meets several images of the same
// neighbour, and its own images, each as its own pair. This is what an infinite periodic
// chain needs (the dipole sums converge like 1/n³, so the cutoff may span many boxes).
//
// A pair stores its two indices and the image shift S such that the pair vector is
//   r = x_j − x_i + S      (raw, unwrapped positions as given at build time).
// A bead wrapped by the DEM between two builds jumps by a box length, which the displacement
// check sees as a large move: the list is then rebuilt and S recomputed.
//
// Construction: a cell list (cells at least the list radius wide), built deterministically
// in two parallel passes (count, then fill); the pair order depends on the positions only,
// never on the number of threads.
#pragma once

#include "common/state_stream.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class MagneticNeighbourList
{
public:
  struct Pair
  {
    std::uint32_t i, j; // i < j, or i == j for a bead and one of its own images
    double shift[3];    // r = x_j − x_i + shift
  };

  // A per-pair reach, for a short-range pair law whose range scales with the pair's size:
  // a pair is listed only when |r| < factor × ½(a_i + a_j) + skin (a_b = radius[b]), which
  // must not exceed the list radius (the cell size of the search).
  struct PairReach
  {
    const double *radius = nullptr; // none: every pair within the list radius
    double factor = 0.0;
    double skin = 0.0;
  };

  // Builds the list of pairs closer than list_radius (and within `reach`, if given);
  // box[d] = periodic length (0 = open).
  void build(std::size_t n, const double *x, const double *y, const double *z,
             const std::array<double, 3> &box, double list_radius, const PairReach &reach);
  void build(std::size_t n, const double *x, const double *y, const double *z,
             const std::array<double, 3> &box, double list_radius)
  {
    build(n, x, y, z, box, list_radius, PairReach());
  }

  // Takes a ready pair set (e.g. the near pairs of the cell-multipole far field) and builds
  // the incidence; positions are kept as the reference for max_displacement. The pairs are
  // taken by swapping, not copied: `pairs` receives the list's previous buffer, emptied, so
  // that its capacity serves the next build (a copy of the ~10⁵–10⁶ pairs and a fresh
  // allocation — page faults on every touch — per rebuild were a third of a rebuild).
  void set_pairs(std::size_t n, const double *x, const double *y, const double *z,
                 const std::array<double, 3> &box, double list_radius, std::vector<Pair> &pairs);

  // Beads appended (indices particle_count() … n−1, positions x, y, z of all n) with their
  // pairs `more` (each touching an appended bead): the pairs join at the end, and the
  // appended beads' positions become their reference; the other beads keep theirs (their
  // displacement still counts from the build). The new pairs' incidence entries go into the
  // spare slots that every row keeps after its entries (see incident_end()), the appended
  // beads' rows after the last row: no earlier entry moves, and the cost is that of the new
  // pairs, not of the list, and it returns true. When some row has no room left, the
  // incidence is laid out afresh (every row with new spare slots) and it returns false.
  // Either way every row lists its pairs in increasing pair order, as a build would.
  bool append(std::size_t n, const double *x, const double *y, const double *z, const std::vector<Pair> &more);
  // Appends that had to lay the incidence out afresh (a row out of spare slots), since the
  // list was built.
  long relayouts() const { return relayouts_; }

  // Forgets the pairs (the bead indices they refer to changed) but keeps the memory: the
  // next build fills the same buffers. built() is false afterwards.
  void clear();

  // Per-block pair buffers of collect_pairs(), kept by the caller between builds so that a
  // rebuild allocates nothing once the buffers have grown.
  struct PairBlocks
  {
    std::vector<std::vector<Pair>> block;
    std::vector<std::size_t> begin;
  };

  // Fills `pairs` in bead order from a neighbour enumerator: the same pairs in the same order
  // on any number of threads. for_each_neighbour(i, emit) calls emit(j, shift) for each
  // partner j of bead i, `shift` (3 doubles) referring to the wrapped coordinates xw (x, y, z
  // interleaved); the stored shift refers to the raw coordinates coord[d][·]:
  // r = x_j − x_i + shift. On one thread a single pass appends the pairs. On several, the
  // beads are cut into fixed blocks (independent of the thread count); each block appends
  // its pairs to a buffer of its own in one pass, and the buffers are then copied to `pairs`
  // in block order. (The enumeration — cell lookups, distances — costs several times the
  // copy: an earlier version ran it twice, to count and then to fill.)
  template <typename ForEachNeighbour>
  static void collect_pairs(std::size_t n, ForEachNeighbour &&for_each_neighbour, const double *xw,
                            const double *const coord[3], std::size_t parallel_threshold,
                            std::vector<Pair> &pairs, PairBlocks &scratch)
  {
    auto make_pair = [&](std::size_t i, std::uint32_t j, const double *shift) {
      Pair p;
      p.i = static_cast<std::uint32_t>(i);
      p.j = j;
      for (int d = 0; d < 3; ++d)
        p.shift[d] = shift[d] + (xw[3 * j + d] - coord[d][j]) - (xw[3 * i + d] - coord[d][i]);
      return p;
    };
    if (n < parallel_threshold || omp_get_max_threads() == 1)
    {
      pairs.clear(); // (keeps the capacity of the last build)
      for (std::size_t i = 0; i < n; ++i)
        for_each_neighbour(i, [&](std::uint32_t j, const double *shift) { pairs.push_back(make_pair(i, j, shift)); });
      return;
    }
    constexpr std::size_t block_beads = 128;
    const long blocks = static_cast<long>((n + block_beads - 1) / block_beads);
    if (scratch.block.size() < static_cast<std::size_t>(blocks))
      scratch.block.resize(blocks);
    scratch.begin.resize(blocks + 1);
#pragma omp parallel
    {
#pragma omp for schedule(dynamic, 1)
      for (long b = 0; b < blocks; ++b)
      {
        std::vector<Pair> &out = scratch.block[b];
        out.clear();
        const std::size_t i1 = std::min(n, (b + 1) * block_beads);
        for (std::size_t i = b * block_beads; i < i1; ++i)
          for_each_neighbour(i, [&](std::uint32_t j, const double *shift) { out.push_back(make_pair(i, j, shift)); });
      }
#pragma omp single
      {
        scratch.begin[0] = 0;
        for (long b = 0; b < blocks; ++b)
          scratch.begin[b + 1] = scratch.begin[b] + scratch.block[b].size();
        pairs.resize(scratch.begin[blocks]);
      }
#pragma omp for schedule(static)
      for (long b = 0; b < blocks; ++b)
        std::copy(scratch.block[b].begin(), scratch.block[b].end(), pairs.begin() + scratch.begin[b]);
    }
  }

  // Largest displacement of any bead since the last build (no minimum image: a wrap counts
  // as a large move).
  double max_displacement(std::size_t n, const double *x, const double *y,
                          const double *z) const;

  bool built() const { return built_; }
  std::size_t size() const { return pairs_.size(); }
  std::size_t particle_count() const { return x_ref_.size() / 3; }
  double list_radius() const { return list_radius_; }
  const std::array<double, 3> &box() const { return box_; }
  const std::vector<Pair> &pairs() const { return pairs_; }
  // The positions at build time (x, y, z interleaved), the reference of max_displacement.
  const std::vector<double> &reference_positions() const { return x_ref_; }

  // Incidence of the pairs on the beads (CSR with spare slots): the pairs touching bead b are
  //   incident_pair[incident_begin[b] .. incident_end[b]), in increasing pair order,
  // with incident_first[q] = 1 when b is the pair's i (0 when its j). A self-image pair
  // appears twice, once as i and once as j. The slots from incident_end[b] to
  // incident_begin[b+1] are spare (room for the pairs of beads appended later; their
  // contents mean nothing), so arrays indexed by slot are incident_begin[n] long.
  const std::vector<std::size_t> &incident_begin() const { return incident_begin_; }
  const std::vector<std::size_t> &incident_end() const { return incident_end_; }
  const std::vector<std::uint32_t> &incident_pair() const { return incident_pair_; }
  const std::vector<std::uint8_t> &incident_first() const { return incident_first_; }

  // Restart (common/state_stream.h): everything above, exactly.
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  bool built_ = false;
  double list_radius_ = 0.0;
  std::array<double, 3> box_{0.0, 0.0, 0.0};
  std::vector<double> x_ref_; // positions at build time (x, y, z interleaved)
  std::vector<Pair> pairs_;
  std::vector<std::size_t> incident_begin_; // n + 1: row b's first slot, then the total
  std::vector<std::size_t> incident_end_;   // n: one past row b's last entry
  std::vector<std::uint32_t> incident_pair_;
  std::vector<std::uint8_t> incident_first_;
  long relayouts_ = 0;

  std::vector<std::size_t> fill_; // build_pair_incidence(), append(): scratch (per thread and bead)
  PairBlocks blocks_;             // build(): collect_pairs()' per-block buffers
  void build_incidence(std::size_t n, const double *const coord[3]);
  void build_pair_incidence(std::size_t n);
  bool append_incidence(std::size_t first_bead, std::size_t n, std::size_t first_pair);
};

} // namespace magbrush::magnetics
