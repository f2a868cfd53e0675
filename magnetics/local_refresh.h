// The local refresh: which beads and pairs to re-evaluate when a few beads moved, so that the
// magnetics can be renewed around them while everything else is held.
//
// A bead's dipole reacts to a moved neighbour like 2β(a/r)³ of the neighbour's relative
// change: beyond a few diameters far below a per cent. So a refresh need not touch the far
// field or the dipoles far away. The sets, each in a fixed order:
//   1. moved:    the beads past their staleness limit, batched (once one bead is past it,
//                every bead past local_batch_fraction of its limit comes along, so that the
//                next one does not trigger another refresh a step later); in the relative
//                mode also the bead(s) that made a watched pair drift (|Δr| ≤ |Δx_i| + |Δx_j|:
//                at least one of them moved half of it);
//   2. region:   the moved beads and their near neighbours within local_region_radius of the
//                moved bead's radius — their dipoles are solved again (Jacobi sweeps with the
//                dipoles outside and the far field held);
//   3. changed:  the moved beads and those of the region whose dipole changed by more than
//                local_dipole_change — their pairs' forces are recomputed (stored once per
//                pair and applied ±: Newton's third law stays exact);
//   4. gathered: every bead touching a recomputed pair — its total force is gathered again.
// This class finds the sets; InducedDipoles::refresh_locally does the physics on them.
#pragma once

#include "magnetics/bead_arrays.h"
#include "magnetics/magnetic_settings.h"
#include "magnetics/near_pairs.h"
#include "magnetics/staleness_tracker.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class LocalRefresh
{
public:
  // 1. The moved beads; false when nothing is past its limit (no refresh due).
  bool select_moved(const BeadArrays &beads, const StalenessTracker &staleness,
                    const MagneticSettings &settings);
  // 1'. The moved beads given (an admission: the newcomers and the leavers), in ascending
  // order, for a refresh of n beads.
  void select_given(const std::vector<std::uint32_t> &beads, std::size_t n);
  // 2. The region around the moved beads (current positions), sorted by bead.
  void grow_region(const BeadArrays &beads, const NearPairs &near, double region_radius);
  // A region larger than `limit` of the beads (and than 64 beads: a small region is always
  // cheaper than a full refresh) is refreshed fully instead.
  bool region_too_large(std::size_t n, double limit) const;
  // The near pairs of the moved beads, each once: their tensors are evaluated again.
  const std::vector<std::uint32_t> &select_moved_pairs(const NearPairs &near);
  // The region's dipoles before its sweeps, and 3. the changed beads after them.
  void hold_region_dipoles(const std::vector<double> &p);
  void select_changed(const std::vector<double> &p, double dipole_change);
  // The near pairs (and `corrected` list pairs, when `correction` is not null) touching a
  // changed bead, each once, and 4. the beads to gather.
  void select_force_pairs(const NearPairs &near, const MagneticNeighbourList *correction);

  const std::vector<std::uint32_t> &moved() const { return moved_; }
  const std::vector<std::uint32_t> &region() const { return region_; }
  const std::vector<std::uint32_t> &moved_pairs() const { return moved_pairs_; }
  const std::vector<std::uint32_t> &force_pairs() const { return force_pairs_; }
  const std::vector<std::uint32_t> &correction_pairs() const { return correction_pairs_; }
  const std::vector<std::uint32_t> &gathered() const { return gathered_; }

private:
  enum : std::uint8_t { in_region = 1, in_gather = 2, is_moved = 4 };
  std::vector<std::uint8_t> bead_mark_;  // the bits above, per bead
  std::vector<std::uint8_t> pair_mark_;  // per near pair: 1 = tensor renewed, 2 = force renewed
  std::vector<std::uint8_t> correction_mark_;
  std::vector<std::uint32_t> moved_, region_, changed_, gathered_;
  std::vector<std::uint32_t> moved_pairs_, force_pairs_, correction_pairs_;
  std::vector<double> region_p_; // the region's dipoles before its sweeps

  // Appends bead b to `list` the first time it is flagged with `bit` (a set kept as a list in
  // first-seen order, with the flags as the membership test).
  void add_once(std::uint8_t bit, std::vector<std::uint32_t> &list, std::uint32_t b)
  {
    if (!(bead_mark_[b] & bit))
    {
      bead_mark_[b] |= bit;
      list.push_back(b);
    }
  }
};

} // namespace magbrush::magnetics
