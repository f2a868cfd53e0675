// When do the held magnetic forces go stale? The bookkeeping of a DEM that evaluates the
// magnetics at an interval and holds the forces in between.
//
// The forces depend on where the beads are, so the tracker keeps every bead's position at
// its last force evaluation and says a refresh is due when
//   * nothing was evaluated yet or the bead count changed;
//   * the refresh interval has elapsed since the last full evaluation;
//   * beads moved: by StalenessMode,
//       absolute, local: some bead moved more than staleness_fraction × its radius;
//       relative:        the dipole–dipole forces depend on RELATIVE positions, so the
//                        watched pairs (closer than relative_check_radius mean radii plus the
//                        skin at the last full evaluation) are stale when their pair vector
//                        changed by more than staleness_fraction × the mean radius; a bead
//                        alone (the applied field, which varies on the mm scale) only when it
//                        moved absolute_factor times that.
// Moves are minimum-image along periodic axes: a bead wrapped by the caller did not move.
// A check costs one pass over the beads; the relative mode reads its watched pairs only
// when one could be stale. |Δr| ≤ |Δx_i| + |Δx_j| bounds a pair's drift by its beads' moves
// twice: since the pair's evaluation (no bead moved half the limit: no pair is stale), and
// since the last pass over the pairs (their largest drift then plus twice the largest bead
// move since is still below the limit). The second bound is what holds in a brush carried
// along by the sleeve, where every bead soon moves half the limit but the pairs barely drift.
// Both only skip work: the verdict is the pass's own.
#pragma once

#include "common/state_stream.h"

#include "magnetics/bead_arrays.h"
#include "magnetics/magnetic_settings.h"
#include "magnetics/near_pairs.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace magbrush::magnetics {

// Why a refresh is due (InducedDipoles::check_staleness).
enum class RefreshReason { none, first, bead_count, interval, moved };

struct StalenessCheck
{
  RefreshReason reason = RefreshReason::none;
  std::size_t stale_beads = 0; // beads past the staleness limit
  std::size_t stale_pairs = 0; // relative mode: watched pairs past it
  double max_move = 0.0;       // largest displacement since the bead's last evaluation / radius
};

class StalenessTracker
{
public:
  // A watched pair, compact for the per-step check: drift = x_j − x_i + c with
  // c = image shift − the pair vector at the tensor's evaluation; stale when
  // |drift|² > limit2 = (staleness_fraction × mean radius)².
  struct ClosePair
  {
    std::uint32_t i, j;
    double c[3];
    double limit2;
  };

  StalenessTracker(const MagneticSettings &settings, const std::array<double, 3> &box);

  // A full evaluation at `time`: every bead's reference position and move limit.
  void evaluated_all(const BeadArrays &beads, double time);
  // A local refresh re-evaluated bead b (the interval still counts from the full one).
  void evaluated(const BeadArrays &beads, std::size_t b);
  // relative: watch the near pairs that can come within relative_check_radius mean radii
  // before the list expires (`skin` [m]).
  void watch_close_pairs(const BeadArrays &beads, const NearPairs &near, double skin);
  // An admission: beads first … n−1 appended (evaluated now: reference positions and limits)
  // with the near pairs from `first_pair` on (relative: watched like watch_close_pairs());
  // the `inert` beads (leavers kept as holes) no longer move anything: their watched pairs
  // are never stale.
  void admit(const BeadArrays &beads, std::size_t first, const NearPairs &near, std::size_t first_pair,
             double skin, const std::vector<std::uint32_t> &inert);
  // Near pair k's tensor was evaluated again: its drift restarts from the current vector.
  void pair_reevaluated(const NearPairs &near, std::size_t k);

  // The interval and the moves since the reference (not "first": the caller knows whether it
  // ever evaluated). `list_current`: the near pairs still refer to these beads. Called by
  // every thread of a team (the passes are shared, every thread gets the verdict) or by one
  // thread outside a parallel region.
  StalenessCheck check(const BeadArrays &beads, double time, bool list_current) const;
  // After a check() whose verdict was "none": how far every bead may still move from where
  // that check saw it (each by at most this much) before a check could say anything else,
  // the refresh interval aside [m]. The bead pass's slack (every bead's distance from its
  // limit), and in the relative mode the distance before the pair pass could be due (no bead
  // moved half the pairs' limit, or the last pair pass's margin not used up). 0 after
  // anything that changes the references (and before any check). A caller that knows a bound
  // on every bead's move since that check (the engine's largest drift per step, summed) may
  // skip the checks until the bound reaches it: they would all say "none".
  double quiet_distance() const { return quiet_distance_; }
  // The refresh interval has elapsed since the last full evaluation (check() says "interval").
  bool interval_due(double time) const
  {
    return settings_.refresh_interval <= 0.0 || time - t_last_ >= settings_.refresh_interval * (1.0 - 1e-9);
  }

  std::size_t reference_count() const { return x_last_.size() / 3; }
  // |x_b − x_last,b|² (minimum image along periodic axes) and its limit [m²].
  double squared_move(const BeadArrays &beads, std::size_t b) const;
  double limit2(std::size_t b) const { return limit2_[b]; }
  const std::vector<ClosePair> &close_pairs() const { return close_; }
  // How many checks read the watched pairs (the rest were decided by the bead moves alone).
  std::size_t pair_passes() const { return pair_passes_; }
  // relative: |Δr|² of a watched pair since its tensor was evaluated [m²].
  static double drift2(const BeadArrays &beads, const ClosePair &c)
  {
    const double d[3] = {beads.x[c.j] - beads.x[c.i] + c.c[0], beads.y[c.j] - beads.y[c.i] + c.c[1],
                         beads.z[c.j] - beads.z[c.i] + c.c[2]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  }

  // The caller re-sorted its beads (new[k] = old[order[k]]): the reference positions follow;
  // the watched pairs are dropped until the next full evaluation.
  void particles_reordered(const std::vector<std::int32_t> &order);

  // Restart (common/state_stream.h): the reference positions, limits and watched pairs.
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  MagneticSettings settings_;
  std::array<double, 3> box_;
  std::vector<double> x_last_; // per bead: position at its last force evaluation
  double t_last_ = 0.0;         // time of the last full evaluation
  std::vector<double> limit2_, inv_radius2_; // per bead: move limit², 1/radius²
  std::vector<ClosePair> close_;
  std::vector<std::int32_t> close_of_pair_; // the record of near pair k (−1 = not watched)
  double min_radius_ = 0.0, max_radius_ = 0.0;
  mutable std::vector<double> move2_; // per-check scratch: |Δx_b|²
  // Per-check scratch: each thread's partial results of the shared passes (own cache line).
  struct alignas(64) CheckPartial
  {
    std::size_t stale = 0, stale_pairs = 0;
    double worst2 = 0.0, pass_move2 = 0.0; // the bead pass: largest |Δx|²/a², largest move² since the pair pass
    double pair_worst = 0.0, min_limit2 = std::numeric_limits<double>::infinity(); // the pair pass
    double slack = std::numeric_limits<double>::infinity(); // the bead pass: min (limit² − |Δx|²) / 2 limit
  };
  mutable std::vector<CheckPartial> partial_;
  // The last pass over the watched pairs: the bead positions then, and a lower bound on every
  // pair's distance from its limit then [m] (< 0: no valid pass; anything that changes the
  // watched pairs or their references invalidates it). A cache of check(), hence mutable.
  mutable std::vector<double> x_pass_;
  mutable double pass_margin_ = -1.0;
  mutable std::size_t pair_passes_ = 0;
  mutable double quiet_distance_ = 0.0; // the last check's (quiet_distance())
  std::vector<double> inv_two_limit_;    // per bead: 1 / (2 × its move limit) [1/m]
  void forget_pair_pass()
  {
    pass_margin_ = -1.0;
    quiet_distance_ = 0.0;
  }
  void set_limit(const BeadArrays &beads, std::size_t b);

  // Bead b's limit on its absolute move [m]: staleness_fraction × radius, times
  // absolute_factor in the relative mode.
  double move_limit(const BeadArrays &beads, std::size_t b) const;
  void watch_pair(const BeadArrays &beads, const NearPairs &near, std::size_t k, double skin);
  // Counts the stale watched pairs and records the pass (x_pass_, pass_margin_).
  std::size_t count_stale_pairs(const BeadArrays &beads) const;
};

} // namespace magbrush::magnetics
