#include "magnetics/local_refresh.h"

#include <algorithm>

namespace magbrush::magnetics {

bool LocalRefresh::select_moved(const BeadArrays &beads, const StalenessTracker &staleness,
                                const MagneticSettings &settings)
{
  const std::size_t n = beads.n;
  moved_.clear();
  bool due = false;
  const double batch2 = settings.local_batch_fraction * settings.local_batch_fraction;
  bead_mark_.assign(n, 0);
  for (std::size_t b = 0; b < n; ++b)
  {
    const double move2 = staleness.squared_move(beads, b);
    due |= move2 > staleness.limit2(b);
    if (move2 > batch2 * staleness.limit2(b))
      add_once(is_moved, moved_, static_cast<std::uint32_t>(b));
  }
  if (settings.staleness_mode == StalenessMode::relative)
  {
    for (const StalenessTracker::ClosePair &p : staleness.close_pairs())
    {
      const double d2 = StalenessTracker::drift2(beads, p);
      due |= d2 > p.limit2;
      if (d2 > batch2 * p.limit2)
      {
        // The bead(s) that made the drift (re-evaluating one re-evaluates the pair).
        const double half2 = 0.25 * d2;
        if (staleness.squared_move(beads, p.i) >= half2)
          add_once(is_moved, moved_, p.i);
        if (staleness.squared_move(beads, p.j) >= half2)
          add_once(is_moved, moved_, p.j);
      }
    }
  }
  if (due)
    std::sort(moved_.begin(), moved_.end());
  return due;
}

void LocalRefresh::select_given(const std::vector<std::uint32_t> &beads, std::size_t n)
{
  moved_.clear();
  bead_mark_.assign(n, 0);
  for (const std::uint32_t b : beads)
    add_once(is_moved, moved_, b);
}

void LocalRefresh::grow_region(const BeadArrays &beads, const NearPairs &near, double region_radius)
{
  const auto &pairs = near.pairs();
  const auto &begin = near.list().incident_begin();
  const auto &end = near.list().incident_end();
  const auto &pair_of = near.list().incident_pair();
  const auto &first = near.list().incident_first();
  region_.clear();
  for (const std::uint32_t b : moved_)
  {
    add_once(in_region, region_, b);
    const double reach = region_radius * beads.radius[b];
    for (std::size_t q = begin[b]; q < end[b]; ++q)
    {
      const auto &pair = pairs[pair_of[q]];
      const double r[3] = {beads.x[pair.j] - beads.x[pair.i] + pair.shift[0],
                           beads.y[pair.j] - beads.y[pair.i] + pair.shift[1],
                           beads.z[pair.j] - beads.z[pair.i] + pair.shift[2]};
      if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < reach * reach)
        add_once(in_region, region_, first[q] ? pair.j : pair.i);
    }
  }
  std::sort(region_.begin(), region_.end()); // a fixed order, whatever the discovery order
}

bool LocalRefresh::region_too_large(std::size_t n, double limit) const
{
  return region_.size() > 64 && static_cast<double>(region_.size()) > limit * static_cast<double>(n);
}

const std::vector<std::uint32_t> &LocalRefresh::select_moved_pairs(const NearPairs &near)
{
  const auto &begin = near.list().incident_begin();
  const auto &end = near.list().incident_end();
  const auto &pair_of = near.list().incident_pair();
  pair_mark_.assign(near.pairs().size(), 0);
  moved_pairs_.clear();
  for (const std::uint32_t b : moved_)
    for (std::size_t q = begin[b]; q < end[b]; ++q)
      if (!pair_mark_[pair_of[q]])
      {
        pair_mark_[pair_of[q]] = 1;
        moved_pairs_.push_back(pair_of[q]);
      }
  return moved_pairs_;
}

void LocalRefresh::hold_region_dipoles(const std::vector<double> &p)
{
  region_p_.resize(3 * region_.size());
  for (std::size_t m = 0; m < region_.size(); ++m)
    for (int d = 0; d < 3; ++d)
      region_p_[3 * m + d] = p[3 * region_[m] + d];
}

void LocalRefresh::select_changed(const std::vector<double> &p, double dipole_change)
{
  changed_.clear();
  const double tol2 = dipole_change * dipole_change;
  for (std::size_t m = 0; m < region_.size(); ++m)
  {
    const std::uint32_t b = region_[m];
    double dp2 = 0.0, p2 = 0.0;
    for (int d = 0; d < 3; ++d)
    {
      const double dp = p[3 * b + d] - region_p_[3 * m + d];
      dp2 += dp * dp;
      p2 += p[3 * b + d] * p[3 * b + d];
    }
    if ((bead_mark_[b] & is_moved) || tol2 == 0.0 || dp2 > tol2 * p2)
      changed_.push_back(b);
  }
}

void LocalRefresh::select_force_pairs(const NearPairs &near, const MagneticNeighbourList *correction)
{
  const auto &pairs = near.pairs();
  const auto &begin = near.list().incident_begin();
  const auto &end = near.list().incident_end();
  const auto &pair_of = near.list().incident_pair();
  gathered_.clear();
  force_pairs_.clear();
  correction_pairs_.clear();
  for (const std::uint32_t b : changed_)
    for (std::size_t q = begin[b]; q < end[b]; ++q)
      if (pair_mark_[pair_of[q]] != 2)
      {
        const std::uint32_t k = pair_of[q];
        pair_mark_[k] = 2;
        force_pairs_.push_back(k);
        add_once(in_gather, gathered_, pairs[k].i);
        add_once(in_gather, gathered_, pairs[k].j);
      }
  if (!correction)
    return;
  const auto &cpairs = correction->pairs();
  const auto &cbegin = correction->incident_begin();
  const auto &cend = correction->incident_end();
  const auto &cpair = correction->incident_pair();
  correction_mark_.assign(cpairs.size(), 0);
  for (const std::uint32_t b : changed_)
    for (std::size_t q = cbegin[b]; q < cend[b]; ++q)
      if (!correction_mark_[cpair[q]])
      {
        const std::uint32_t k = cpair[q];
        correction_mark_[k] = 1;
        correction_pairs_.push_back(k);
        add_once(in_gather, gathered_, cpairs[k].i);
        add_once(in_gather, gathered_, cpairs[k].j);
      }
}

} // namespace magbrush::magnetics
