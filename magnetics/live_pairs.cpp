// The close pairs' forces following the beads between evaluations (see live_pairs.h).
#include "magnetics/live_pairs.h"

#include "magnetics/dipole_physics.h"

#include <omp.h>

namespace magbrush::magnetics {

void LivePairs::clear()
{
  pair_.clear();
  ends_.clear();
  live_of_.clear();
  base_.clear();
  change_.clear();
  start_.clear();
  entry_.clear();
  bead_change_.clear();
  beads_ = 0;
  calls_ = 0;
}

void LivePairs::select(const BeadArrays &beads, const NearPairs &near, double reach_factor)
{
  pair_.clear();
  ends_.clear();
  live_of_.clear();
  base_.clear();
  append(beads, near, 0, reach_factor);
}

void LivePairs::append(const BeadArrays &beads, const NearPairs &near, std::size_t first_pair, double reach_factor)
{
  live_of_.resize(near.pairs().size(), -1);
  for (std::size_t k = first_pair; k < near.pairs().size(); ++k)
    consider(beads, near, k, reach_factor);
  beads_ = beads.n;
  base_.resize(3 * pair_.size(), 0.0);
  build_incidence();
  change_.resize(3 * pair_.size());
  calls_ = 0;
}

void LivePairs::consider(const BeadArrays &beads, const NearPairs &near, std::size_t k, double reach_factor)
{
  const auto &pair = near.pairs()[k];
  // (A bead's own periodic image is a period away; an inert hole has no dipole.)
  if (pair.i == pair.j || !near.active(k) ||
      (beads.mu_r && (beads.mu_r[pair.i] == 1.0 || beads.mu_r[pair.j] == 1.0)))
    return;
  // (No skin: a pair that comes closer later is held like any other pair until the next
  // selection; a skin of 0.3 diameters would triple the live pairs of a dense bed.)
  const double a = 0.5 * (beads.radius[pair.i] + beads.radius[pair.j]);
  const double reach = reach_factor * a;
  const double *r = near.r(k);
  if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= reach * reach)
    return;
  live_of_[k] = static_cast<std::int32_t>(pair_.size());
  pair_.push_back(static_cast<std::uint32_t>(k));
  ends_.push_back(pair);
}

// The incidence, in ascending live index per bead: a bead's sum runs in a fixed order.
void LivePairs::build_incidence()
{
  start_.assign(beads_ + 1, 0);
  for (const auto &pair : ends_)
  {
    ++start_[pair.i + 1];
    ++start_[pair.j + 1];
  }
  for (std::size_t b = 0; b < beads_; ++b)
    start_[b + 1] += start_[b];
  entry_.resize(start_[beads_]);
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t m = 0; m < pair_.size(); ++m)
  {
    const auto &pair = ends_[m];
    entry_[fill[pair.j]++] = static_cast<std::int32_t>(m + 1);
    entry_[fill[pair.i]++] = -static_cast<std::int32_t>(m + 1);
  }
}

void LivePairs::pair_force(const InducedState &s, const TwoSphereCorrection *correction, std::size_t m,
                           double F[3]) const
{
  const auto &pair = ends_[m];
  const std::uint32_t i = pair.i, j = pair.j;
  const double r[3] = {s.beads.x[j] - s.beads.x[i] + pair.shift[0], s.beads.y[j] - s.beads.y[i] + pair.shift[1],
                       s.beads.z[j] - s.beads.z[i] + pair.shift[2]};
  dipole_pair_force(r, &s.p[3 * j], &s.p[3 * i], F); // the force on j from i
  if (correction)
    correction->add(s, i, j, r, DipoleTensor::at(r), F);
}

void LivePairs::rebase_all(const InducedState &s, const TwoSphereCorrection *correction)
{
  const long n = static_cast<long>(pair_.size());
#pragma omp parallel for schedule(static) if (n >= static_cast<long>(bead_parallel_threshold))
  for (long m = 0; m < n; ++m)
    pair_force(s, correction, static_cast<std::size_t>(m), &base_[3 * m]);
  calls_ = 0;
}

void LivePairs::rebase(const InducedState &s, const TwoSphereCorrection *correction,
                       const std::vector<std::uint32_t> &near_pairs)
{
  const long n = static_cast<long>(near_pairs.size());
#pragma omp parallel for schedule(static) if (n >= static_cast<long>(bead_parallel_threshold))
  for (long q = 0; q < n; ++q)
  {
    const std::uint32_t k = near_pairs[static_cast<std::size_t>(q)];
    if (k >= live_of_.size() || live_of_[k] < 0)
      continue;
    const auto m = static_cast<std::size_t>(live_of_[k]);
    pair_force(s, correction, m, &base_[3 * m]);
  }
  calls_ = 0;
}

const std::vector<double> &LivePairs::update(const InducedState &s, const TwoSphereCorrection *correction)
{
  // The changes are evaluated every `every_` calls (and at the first call after a rebase) and
  // held in between: in one step a pair moves ~10⁻⁴ of a radius, far below the staleness
  // limit that sets the dipoles' own refresh.
  if (due())
  {
#pragma omp parallel if (pair_.size() >= bead_parallel_threshold)
    evaluate_changes(s, correction);
  }
  ++calls_;
  return bead_change_;
}

const std::vector<double> &LivePairs::update_in_team(const InducedState &s, const TwoSphereCorrection *correction)
{
  if (due())
    evaluate_changes(s, correction);
  // (Every thread has read the count, in due(), before it advances.)
#pragma omp barrier
#pragma omp single nowait
  ++calls_;
  return bead_change_;
}

void LivePairs::evaluate_changes(const InducedState &s, const TwoSphereCorrection *correction)
{
  const long n = static_cast<long>(pair_.size());
  const long nb = static_cast<long>(beads_);
#pragma omp single
  bead_change_.resize(3 * beads_);
#pragma omp for schedule(static)
  for (long m = 0; m < n; ++m)
  {
    double F[3];
    pair_force(s, correction, static_cast<std::size_t>(m), F);
    for (int d = 0; d < 3; ++d)
      change_[3 * m + d] = F[d] - base_[3 * m + d];
  }
#pragma omp for schedule(static)
  for (long b = 0; b < nb; ++b)
  {
    double f[3] = {0.0, 0.0, 0.0};
    for (std::uint32_t e = start_[b]; e < start_[b + 1]; ++e)
    {
      const std::int32_t v = entry_[e];
      const double sign = v > 0 ? 1.0 : -1.0;
      const std::size_t m = static_cast<std::size_t>(v > 0 ? v - 1 : -v - 1);
      for (int d = 0; d < 3; ++d)
        f[d] += sign * change_[3 * m + d];
    }
    for (int d = 0; d < 3; ++d)
      bead_change_[3 * b + d] = f[d];
  }
}

void LivePairs::scale(double ratio2)
{
  for (auto *v : {&base_, &change_, &bead_change_})
    for (double &x : *v)
      x *= ratio2;
}

void LivePairs::write_state(StateOut &out) const
{
  out.put_array(pair_);
  out.put_array(base_);
  out.put(calls_);
  out.put_array(bead_change_);
}

void LivePairs::read_state(StateIn &in, std::size_t beads, const NearPairs &near)
{
  const std::size_t near_pairs = near.pairs().size();
  in.get_array(pair_);
  in.get_array(base_);
  calls_ = in.get<long>();
  in.get_array(bead_change_);
  if (base_.size() != 3 * pair_.size())
    in.fail("is corrupt (live pairs and their base forces differ in number)");
  live_of_.assign(near_pairs, -1);
  ends_.clear();
  for (std::size_t m = 0; m < pair_.size(); ++m)
  {
    if (pair_[m] >= near_pairs)
      in.fail("is corrupt (a live pair beyond the near pairs)");
    live_of_[pair_[m]] = static_cast<std::int32_t>(m);
    ends_.push_back(near.pairs()[pair_[m]]);
  }
  beads_ = beads;
  build_incidence();
  change_.resize(3 * pair_.size());
}

} // namespace magbrush::magnetics
