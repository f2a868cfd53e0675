#include "magnetics/staleness_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <omp.h>

namespace magbrush::magnetics {

StalenessTracker::StalenessTracker(const MagneticSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box)
{
}

double StalenessTracker::move_limit(const BeadArrays &beads, std::size_t b) const
{
  const double factor = settings_.staleness_mode == StalenessMode::relative ? settings_.absolute_factor : 1.0;
  return factor * settings_.staleness_fraction * beads.radius[b];
}

void StalenessTracker::set_limit(const BeadArrays &beads, std::size_t b)
{
  const double limit = move_limit(beads, b);
  limit2_[b] = limit * limit;
  inv_two_limit_[b] = limit > 0.0 ? 0.5 / limit : 0.0;
  inv_radius2_[b] = 1.0 / (beads.radius[b] * beads.radius[b]);
}

void StalenessTracker::evaluated_all(const BeadArrays &beads, double time)
{
  limit2_.resize(beads.n);
  inv_two_limit_.resize(beads.n);
  inv_radius2_.resize(beads.n);
  for (std::size_t b = 0; b < beads.n; ++b)
    set_limit(beads, b);
  for (std::size_t b = 0; b < beads.n; ++b)
    evaluated(beads, b);
  t_last_ = time;
}

void StalenessTracker::evaluated(const BeadArrays &beads, std::size_t b)
{
  forget_pair_pass();
  x_last_.resize(3 * beads.n);
  x_last_[3 * b] = beads.x[b];
  x_last_[3 * b + 1] = beads.y[b];
  x_last_[3 * b + 2] = beads.z[b];
}

void StalenessTracker::watch_close_pairs(const BeadArrays &beads, const NearPairs &near, double skin)
{
  forget_pair_pass();
  const auto &pairs = near.pairs();
  close_.clear();
  close_of_pair_.assign(pairs.size(), -1);
  min_radius_ = *std::min_element(beads.radius, beads.radius + beads.n);
  max_radius_ = *std::max_element(beads.radius, beads.radius + beads.n);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    watch_pair(beads, near, k, skin);
}

void StalenessTracker::watch_pair(const BeadArrays &beads, const NearPairs &near, std::size_t k, double skin)
{
  const auto &pair = near.pairs()[k];
  // (A bead that does not magnetise, such as an admitted leaver's inert hole, moves no force.)
  if (!near.active(k) || (beads.mu_r && (beads.mu_r[pair.i] == 1.0 || beads.mu_r[pair.j] == 1.0)))
    return;
  const double f = settings_.staleness_fraction;
  const double a = 0.5 * (beads.radius[pair.i] + beads.radius[pair.j]);
  const double reach = settings_.relative_check_radius * a + skin;
  const double *r = near.r(k);
  if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= reach * reach)
    return;
  close_of_pair_[k] = static_cast<std::int32_t>(close_.size());
  close_.push_back({pair.i, pair.j, {0, 0, 0}, f * f * a * a});
  pair_reevaluated(near, k);
}

void StalenessTracker::admit(const BeadArrays &beads, std::size_t first, const NearPairs &near,
                             std::size_t first_pair, double skin, const std::vector<std::uint32_t> &inert)
{
  forget_pair_pass();
  limit2_.resize(beads.n);
  inv_two_limit_.resize(beads.n);
  inv_radius2_.resize(beads.n);
  for (std::size_t b = first; b < beads.n; ++b)
  {
    set_limit(beads, b);
    evaluated(beads, b);
    min_radius_ = std::min(min_radius_, beads.radius[b]);
    max_radius_ = std::max(max_radius_, beads.radius[b]);
  }
  if (settings_.staleness_mode != StalenessMode::relative || close_of_pair_.size() != first_pair)
    return;
  const auto &begin = near.list().incident_begin();
  const auto &end = near.list().incident_end();
  const auto &pair_of = near.list().incident_pair();
  // (An inert bead's pairs include those a newcomer just formed with it, k ≥ first_pair,
  // which are not watched yet: watch_pair() below skips them as inert.)
  for (const std::uint32_t b : inert)
    for (std::size_t q = begin[b]; q < end[b]; ++q)
      if (pair_of[q] < first_pair && close_of_pair_[pair_of[q]] >= 0)
        close_[static_cast<std::size_t>(close_of_pair_[pair_of[q]])].limit2 = std::numeric_limits<double>::infinity();
  close_of_pair_.resize(near.pairs().size(), -1);
  for (std::size_t k = first_pair; k < near.pairs().size(); ++k)
    watch_pair(beads, near, k, skin);
}

void StalenessTracker::pair_reevaluated(const NearPairs &near, std::size_t k)
{
  forget_pair_pass();
  if (close_of_pair_.size() != near.pairs().size() || close_of_pair_[k] < 0)
    return;
  ClosePair &c = close_[static_cast<std::size_t>(close_of_pair_[k])];
  for (int d = 0; d < 3; ++d)
    c.c[d] = near.pairs()[k].shift[d] - near.r(k)[d];
}

StalenessCheck StalenessTracker::check(const BeadArrays &beads, double time, bool list_current) const
{
  // (Every thread of the calling team runs this, or one thread outside a parallel region: the
  // passes are shared with `omp for`, each thread keeps its partial results, and every thread
  // combines them in thread order, so all return the same verdict on any number of threads.
  // The early returns depend on shared data only: every thread takes them alike.)
  StalenessCheck c;
  if (x_last_.size() != 3 * beads.n)
  {
    c.reason = RefreshReason::bead_count;
    return c;
  }
  if (interval_due(time))
  {
    c.reason = RefreshReason::interval;
    return c;
  }
  // A bead is stale when it moved more than its limit since its force was evaluated. The
  // minimum image: a bead wrapped across a periodic face by the caller did not move (the
  // neighbour lists see the jump and are rebuilt at the next full evaluation).
  const bool relative = settings_.staleness_mode == StalenessMode::relative && list_current;
  const bool since_pass = relative && pass_margin_ > 0.0 && x_pass_.size() == 3 * beads.n;
#pragma omp single
  {
    if (relative)
      move2_.resize(beads.n);
    partial_.assign(static_cast<std::size_t>(omp_get_num_threads()), CheckPartial());
  }
  CheckPartial &mine = partial_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
  for (long bl = 0; bl < static_cast<long>(beads.n); ++bl)
  {
    const auto b = static_cast<std::size_t>(bl);
    const double move2 = squared_move(beads, b);
    mine.stale += move2 > limit2_[b];
    mine.worst2 = std::max(mine.worst2, move2 * inv_radius2_[b]);
    // limit − |Δx| ≥ (limit² − |Δx|²) / (2 limit) while |Δx| ≤ limit: no square root per bead.
    mine.slack = std::min(mine.slack, (limit2_[b] - move2) * inv_two_limit_[b]);
    if (relative)
      move2_[b] = move2;
    if (since_pass) // (no minimum image: a wrapped bead's jump forces the pass, as it must)
    {
      const double d[3] = {beads.x[b] - x_pass_[3 * b], beads.y[b] - x_pass_[3 * b + 1],
                           beads.z[b] - x_pass_[3 * b + 2]};
      mine.pass_move2 = std::max(mine.pass_move2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
  }
  std::size_t stale = 0;
  double worst2 = 0.0, pass_move2 = 0.0, slack = std::numeric_limits<double>::infinity();
  for (const CheckPartial &p : partial_)
  {
    stale += p.stale;
    worst2 = std::max(worst2, p.worst2);
    pass_move2 = std::max(pass_move2, p.pass_move2);
    slack = std::min(slack, p.slack);
  }
  c.stale_beads = stale;
  c.max_move = std::sqrt(worst2);
  // relative: a pair can only be stale if one of its beads moved half its limit since its
  // evaluation, or if twice the largest move since the last pass used up the margin that
  // pass left (the header). Otherwise the pass is skipped: it would count no pair.
  const bool some_bead_moved = 2.0 * c.max_move * max_radius_ > settings_.staleness_fraction * min_radius_;
  const bool margin_used = !since_pass || 4.0 * pass_move2 >= pass_margin_ * pass_margin_ * (1.0 - 1e-9);
  const bool pair_pass = relative && some_bead_moved && margin_used;
  if (pair_pass)
    c.stale_pairs = count_stale_pairs(beads);
  if (stale > 0 || c.stale_pairs > 0)
    c.reason = RefreshReason::moved;
  // How far every bead may move from here before a check could say anything else: the
  // beads' slack, and (relative) the distance before the pair pass could be due — before a
  // bead reaches half the pairs' limit (it moves at most d / a_min radii more), or before
  // twice the moves since the last pass use up its margin (a pass now: from its new margin).
  double quiet = c.reason == RefreshReason::none ? slack : 0.0;
  if (relative && quiet > 0.0)
  {
    const double half_pair_limit = 0.5 * settings_.staleness_fraction * min_radius_ / max_radius_; // [radii]
    const double before_half = min_radius_ * (half_pair_limit - c.max_move);
    // (After a pass now the moves count from here; otherwise from the last pass.)
    const double margin = (pair_pass || since_pass) ? pass_margin_ : -1.0;
    const double moved_since_pass = pair_pass ? 0.0 : std::sqrt(pass_move2);
    const double before_margin = margin > 0.0 ? 0.5 * margin * std::sqrt(1.0 - 1e-9) - moved_since_pass : 0.0;
    quiet = std::min(quiet, std::max({before_half, before_margin, 0.0}));
  }
  // (Every thread has the same value; the next step reads it, after the barriers between.)
#pragma omp master
  quiet_distance_ = std::max(0.0, quiet * (1.0 - 1e-6));
  return c;
}

std::size_t StalenessTracker::count_stale_pairs(const BeadArrays &beads) const
{
  // Pairs of beads that have not moved half the pair's limit are not counted. Every pair's
  // drift is measured all the same, for the margin: |Δr| ≤ sqrt(worst) L_p for the largest
  // ratio worst = |Δr|² / L_p², so each pair is at least (1 − sqrt(worst)) L_min from its
  // limit L_p ≥ L_min (one square root per pass, none per pair). Shared like check().
  CheckPartial &mine = partial_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
  for (long k = 0; k < static_cast<long>(close_.size()); ++k)
  {
    const ClosePair &p = close_[static_cast<std::size_t>(k)];
    const double d2 = drift2(beads, p);
    if (4.0 * std::max(move2_[p.i], move2_[p.j]) > p.limit2)
      mine.stale_pairs += d2 > p.limit2;
    mine.pair_worst = std::max(mine.pair_worst, d2 / p.limit2);
    mine.min_limit2 = std::min(mine.min_limit2, p.limit2);
  }
  std::size_t stale_pairs = 0;
  double worst = 0.0, min_limit2 = std::numeric_limits<double>::infinity();
  for (const CheckPartial &p : partial_)
  {
    stale_pairs += p.stale_pairs;
    worst = std::max(worst, p.pair_worst);
    min_limit2 = std::min(min_limit2, p.min_limit2);
  }
  // The pass's record. (Every thread has read x_pass_ and pass_margin_ in check()'s bead
  // loop, before the barrier that ended the loop above.)
#pragma omp single
  {
    ++pair_passes_;
    pass_margin_ = std::isfinite(min_limit2) ? (1.0 - std::sqrt(worst)) * std::sqrt(min_limit2) : -1.0;
    x_pass_.resize(3 * beads.n);
  }
#pragma omp for schedule(static)
  for (long bl = 0; bl < static_cast<long>(beads.n); ++bl)
  {
    const auto b = static_cast<std::size_t>(bl);
    x_pass_[3 * b] = beads.x[b];
    x_pass_[3 * b + 1] = beads.y[b];
    x_pass_[3 * b + 2] = beads.z[b];
  }
  return stale_pairs;
}

double StalenessTracker::squared_move(const BeadArrays &beads, std::size_t b) const
{
  double d[3] = {beads.x[b] - x_last_[3 * b], beads.y[b] - x_last_[3 * b + 1],
                 beads.z[b] - x_last_[3 * b + 2]};
  for (int a = 0; a < 3; ++a)
    if (box_[a] > 0.0 && std::abs(d[a]) > 0.5 * box_[a])
      d[a] -= box_[a] * std::round(d[a] / box_[a]);
  return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

void StalenessTracker::particles_reordered(const std::vector<std::int32_t> &order)
{
  forget_pair_pass();
  if (x_last_.size() == 3 * order.size())
  {
    const std::vector<double> old(x_last_);
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int d = 0; d < 3; ++d)
        x_last_[3 * k + d] = old[3 * static_cast<std::size_t>(order[k]) + d];
  }
  close_.clear();
  close_of_pair_.clear();
}

void StalenessTracker::write_state(StateOut &out) const
{
  out.put_array(x_last_);
  out.put(t_last_);
  out.put_array(limit2_);
  out.put_array(inv_radius2_);
  out.put_array(close_);
  out.put_array(close_of_pair_);
  out.put(min_radius_);
  out.put(max_radius_);
}

void StalenessTracker::read_state(StateIn &in)
{
  forget_pair_pass();
  in.get_array(x_last_);
  t_last_ = in.get<double>();
  in.get_array(limit2_);
  inv_two_limit_.resize(limit2_.size());
  for (std::size_t b = 0; b < limit2_.size(); ++b)
    inv_two_limit_[b] = limit2_[b] > 0.0 ? 0.5 / std::sqrt(limit2_[b]) : 0.0;
  in.get_array(inv_radius2_);
  in.get_array(close_);
  in.get_array(close_of_pair_);
  min_radius_ = in.get<double>();
  max_radius_ = in.get<double>();
}

} // namespace magbrush::magnetics
