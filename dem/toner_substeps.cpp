// The toner's substeps (toner_substeps.h): the number of substeps, the fast pairs of each
// list, and the substeps of one step. Members of DemSystem, like the step's other phases.
#include "dem/dem_system.h"

#include "dem/pair_kernel.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace magbrush::dem {

namespace {
std::size_t U(std::int32_t v) { return static_cast<std::size_t>(v); }
} // namespace

// The step is the carriers' and the toner takes k substeps of the step the whole scene would
// need (dt_ on entry: automatic, or the user's). k is the user's, or (0) the largest that
// keeps the step within the carriers' own limit — the limit of the scene without the toner
// and every contact it takes part in — by the same rule as the single step (the safety
// factor for an automatic step, the limit itself for a user's).
void DemSystem::configure_substeps(const std::vector<Material> &materials, const std::vector<std::string> &names,
                                   const ParticleState &all)
{
  substeps_ = TonerSubsteps{};
  const int asked = case_.dem.toner_substeps;
  substeps_.species_fast.assign(case_.populations.size(), 0);
  bool any_fast = false, any_slow = false;
  for (std::size_t s = 0; s < case_.populations.size(); ++s)
  {
    const bool toner = case_.populations[s].kind == ParticleKind::toner;
    substeps_.species_fast[s] = toner ? 1 : 0;
    (toner ? any_fast : any_slow) = true;
  }
  if (asked == 1 || (asked == 0 && (!any_fast || !any_slow)))
    return;
  if (!any_fast || !any_slow)
    throw std::invalid_argument("dem.toner_substeps = " + std::to_string(asked) + ": the case has " +
                                (any_fast ? "only toner populations" : "no toner population") +
                                "; substeps need toner to subcycle and carriers to set the step (use 1)");
  const StableTimeStep slow = stable_time_step(all, materials, names, table_, walls_.size(), stable_.impact_speed,
                                               &substeps_.species_fast);
  const double allowed = case_.dem.time_step > 0.0 ? slow.limit : case_.dem.time_step_safety * slow.limit;
  const int k_max = std::max(1, static_cast<int>(std::floor(allowed / dt_ * (1.0 + 1e-12))));
  if (asked > k_max)
  {
    char msg[512];
    std::snprintf(msg, sizeof msg,
                  "dem.toner_substeps = %d makes the step %d x %.4g s = %.4g s, above the carriers' own stable step "
                  "%.4g s (%s%s): use at most %d, or 0 for as many as that allows",
                  asked, asked, dt_, asked * dt_, allowed, slow.limiting.c_str(),
                  case_.dem.time_step > 0.0 ? "" : ", times dem.time_step_safety", k_max);
    throw std::invalid_argument(msg);
  }
  const int k = asked == 0 ? k_max : asked;
  if (k == 1)
    return;
  substeps_.substeps = k;
  substeps_.substep = dt_;
  dt_ = k * dt_;
  substeps_.carrier_limit = allowed;
  substeps_.carrier_limiting = slow.limiting;
}

// The fast pairs of the list just built, their members, and the slow particles they reach.
// A slow particle's fast reaction starts from zero (only the slow partners get one).
void DemSystem::find_fast_pairs()
{
  if (!substeps_.on())
    return;
  TonerSubsteps &S = substeps_;
  const ParticleState &s = particles_;
  const NeighbourList &L = list_;
  const std::size_t n = s.size(), P = L.pairs();
  S.skip.assign(P, 0);
  S.pair.clear();
  S.owner.clear();
  S.partner.clear();
  S.image.clear();
  S.movers.clear();
  S.dragged.clear();
  S.mark.assign(n, 0);
  for (std::size_t p = 0; p < P; ++p)
  {
    const std::int32_t i = L.owner[p], j = L.partner[p];
    const bool fi = S.fast(s.species[U(i)]), fj = S.fast(s.species[U(j)]);
    if (!fi && !fj)
      continue;
    S.skip[p] = 1;
    S.pair.push_back(static_cast<std::int32_t>(p));
    S.owner.push_back(i);
    S.partner.push_back(j);
    S.image.push_back(L.image[p]);
    if (!fi)
      S.mark[U(i)] = 1;
    if (!fj)
      S.mark[U(j)] = 1;
  }
  ForceBuffers &f = forces_;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (S.fast(s.species[i]))
    {
      S.movers.push_back(static_cast<std::int32_t>(i));
      continue;
    }
    if (S.mark[i])
      S.dragged.push_back(static_cast<std::int32_t>(i));
    f.fast().zero(i);
  }
  const std::size_t m = S.pair.size();
  for (auto *a : {&S.hx, &S.hy, &S.hz, &S.fx, &S.fy, &S.fz, &S.tix, &S.tiy, &S.tiz, &S.tjx, &S.tjy, &S.tjz})
    a->resize(m);
  S.touching.resize(m);
  for (auto *a : {&S.end_x, &S.end_y, &S.end_z})
    a->resize(S.dragged.size());
  for (auto *a : {&S.start_x, &S.start_y, &S.start_z})
    a->resize(S.movers.size());
  // Each member's pairs in ascending pair order (a counting sort over the pairs).
  S.member_of.assign(n, -1);
  for (std::size_t k = 0; k < S.movers.size(); ++k)
    S.member_of[U(S.movers[k])] = static_cast<std::int32_t>(k);
  for (std::size_t k = 0; k < S.dragged.size(); ++k)
    S.member_of[U(S.dragged[k])] = static_cast<std::int32_t>(k);
  S.mover_begin.assign(S.movers.size() + 1, 0);
  S.dragged_begin.assign(S.dragged.size() + 1, 0);
  auto begin_of = [&](std::int32_t i) -> std::vector<std::int32_t> & {
    return S.fast(s.species[U(i)]) ? S.mover_begin : S.dragged_begin;
  };
  for (std::size_t q = 0; q < m; ++q)
    for (const std::int32_t i : {S.owner[q], S.partner[q]})
      ++begin_of(i)[U(S.member_of[U(i)]) + 1];
  for (auto *b : {&S.mover_begin, &S.dragged_begin})
    for (std::size_t k = 1; k < b->size(); ++k)
      (*b)[k] += (*b)[k - 1];
  S.mover_pairs.resize(U(S.mover_begin.back()));
  S.dragged_pairs.resize(U(S.dragged_begin.back()));
  std::vector<std::int32_t> mover_fill(S.mover_begin.begin(), S.mover_begin.end() - 1),
      dragged_fill(S.dragged_begin.begin(), S.dragged_begin.end() - 1);
  for (std::size_t q = 0; q < m; ++q)
    for (int side = 0; side < 2; ++side)
    {
      const std::int32_t i = side == 0 ? S.owner[q] : S.partner[q];
      const bool fast = S.fast(s.species[U(i)]);
      std::int32_t &slot = (fast ? mover_fill : dragged_fill)[U(S.member_of[U(i)])];
      (fast ? S.mover_pairs : S.dragged_pairs)[U(slot++)] = static_cast<std::int32_t>(2 * q + U(side));
    }
}

// The fast pairs' history and touching flags between the list's slots (where the rebuild,
// the checkpoint and the diagnostics find them) and the substeps' compact copy.
void DemSystem::copy_fast_history(bool into_list)
{
  TonerSubsteps &S = substeps_;
  const long m = static_cast<long>(S.pair.size());
#pragma omp for schedule(static)
  for (long ql = 0; ql < m; ++ql)
  {
    const std::size_t q = static_cast<std::size_t>(ql), p = U(S.pair[q]);
    double *list[3] = {&list_.hist_x[p], &list_.hist_y[p], &list_.hist_z[p]};
    double *compact[3] = {&S.hx[q], &S.hy[q], &S.hz[q]};
    for (int d = 0; d < 3; ++d)
      (into_list ? *list[d] : *compact[d]) = (into_list ? *compact[d] : *list[d]);
    (into_list ? list_.touching[p] : S.touching[q]) = (into_list ? S.touching[q] : list_.touching[p]);
  }
}

// The fast contacts at the current positions, with step dt (the history advances by dt): each
// fast particle's force and torque from zero into forces_.fast_*, its pairs first (in pair
// order), then its walls; each slow member's reaction added to theirs. Work-shared: every thread
// of the team calls it (or one thread alone, outside the team). Returns 1 when a fast pair
// overlaps beyond the guard (this thread's share).
int DemSystem::fast_forces(double dt, StepFlags &mine)
{
  TonerSubsteps &S = substeps_;
  const ForceArrays fast = forces_.fast();
  int alarm = 0;
  const long m = static_cast<long>(S.pair.size());
  if (m > 0)
  {
    PairKernelData D = pair_kernel_data();
    D.owner = S.owner.data();
    D.partner = S.partner.data();
    D.image = S.image.data();
    D.hx = S.hx.data();
    D.hy = S.hy.data();
    D.hz = S.hz.data();
    D.fx = S.fx.data();
    D.fy = S.fy.data();
    D.fz = S.fz.data();
    D.tjx = S.tjx.data();
    D.tjy = S.tjy.data();
    D.tjz = S.tjz.data();
    D.touching = S.touching.data();
    D.slot_base = 0;
    D.dt = dt;
    D.skip = nullptr;
    // The pairs in one block per thread: each writes only its own slot (torques on i indexed
    // from the block's first pair).
    const long threads = omp_in_parallel() ? omp_get_num_threads() : 1, me = omp_in_parallel() ? omp_get_thread_num() : 0;
    const long begin = m * me / threads, end = m * (me + 1) / threads;
    const RowTorques T{S.tix.data() + begin, S.tiy.data() + begin, S.tiz.data() + begin};
    if (end > begin)
      alarm = particle_pair_kernel(D, T, begin, end);
  }
#pragma omp barrier
  // Each particle sums its own pairs, in pair order: the owner gets the pair's force and torque
  // on i, the partner the opposite force and the torque on j.
  auto add_pairs = [&](std::size_t i, const std::int32_t *e, const std::int32_t *e_end) {
    for (; e < e_end; ++e)
    {
      const std::size_t q = U(*e >> 1);
      if ((*e & 1) == 0)
      {
        const double f[3] = {S.fx[q], S.fy[q], S.fz[q]}, t[3] = {S.tix[q], S.tiy[q], S.tiz[q]};
        fast.add(i, f, t);
      }
      else
      {
        const double f[3] = {-S.fx[q], -S.fy[q], -S.fz[q]}, t[3] = {S.tjx[q], S.tjy[q], S.tjz[q]};
        fast.add(i, f, t);
      }
    }
  };
  long wall_alarm = -1, too_many = -1;
  const long movers = static_cast<long>(S.movers.size()), dragged = static_cast<long>(S.dragged.size());
#pragma omp for schedule(static) nowait
  for (long n = 0; n < movers; ++n)
  {
    const std::size_t k = static_cast<std::size_t>(n), i = U(S.movers[k]);
    fast.zero(i);
    add_pairs(i, S.mover_pairs.data() + S.mover_begin[k], S.mover_pairs.data() + S.mover_begin[k + 1]);
    if (walls_.size() > 0)
      particle_wall_contacts(i, dt, fast, wall_alarm, too_many);
  }
#pragma omp for schedule(static)
  for (long n = 0; n < dragged; ++n)
  {
    const std::size_t k = static_cast<std::size_t>(n);
    add_pairs(U(S.dragged[k]), S.dragged_pairs.data() + S.dragged_begin[k],
              S.dragged_pairs.data() + S.dragged_begin[k + 1]);
  }
  if (walls_.size() > 0)
    record_wall_alarms(mine, wall_alarm, too_many);
  return alarm;
}

// The forces at the start, before the first step: the fast contacts as the slow ones (the
// history advances by one substep, as every pair's does by one step), the slow members'
// reaction added to their forces at once. (Outside the team: one thread.)
void DemSystem::initial_fast_forces(StepFlags &mine)
{
  TonerSubsteps &S = substeps_;
  ForceBuffers &f = forces_;
  for (const std::int32_t d : S.dragged)
  {
    const std::size_t du = U(d);
    f.fast().zero(du);
  }
  copy_fast_history(false);
  mine.overlap_alarm |= fast_forces(S.substep, mine);
  copy_fast_history(true);
  for (const std::int32_t d : S.dragged)
  {
    const std::size_t du = U(d);
    f.add_fast_to_main(du);
  }
}

// One step's substeps (toner_substeps.h, item 3). Every thread of the team calls it and takes
// its share of each loop; the phase ends with a barrier (the slow pass needs the fast pairs'
// history back in the list, and the held terms need this step's largest move).
void DemSystem::toner_substeps_phase(StepFlags &mine)
{
  TonerSubsteps &S = substeps_;
  ParticleState &s = particles_;
  ForceBuffers &f = forces_;
  const int k = S.substeps;
  const double delta = S.substep, h = 0.5 * delta;
  const long movers = static_cast<long>(S.movers.size()), dragged = static_cast<long>(S.dragged.size());
  // The slow partners: where their drift ends, and their reaction from zero; the movers' start.
#pragma omp for schedule(static) nowait
  for (long n = 0; n < dragged; ++n)
  {
    const std::size_t m = static_cast<std::size_t>(n), d = U(S.dragged[m]);
    S.end_x[m] = s.x[d];
    S.end_y[m] = s.y[d];
    S.end_z[m] = s.z[d];
    f.fast().zero(d);
  }
#pragma omp for schedule(static) nowait
  for (long n = 0; n < movers; ++n)
  {
    const std::size_t i = U(S.movers[static_cast<std::size_t>(n)]);
    S.start_x[static_cast<std::size_t>(n)] = s.x[i];
    S.start_y[static_cast<std::size_t>(n)] = s.y[i];
    S.start_z[static_cast<std::size_t>(n)] = s.z[i];
  }
  copy_fast_history(false); // (ends with a barrier)
  // A fast particle's kick: the held force of the step plus its fast force.
  auto kick = [&](std::size_t i) {
    const double im = s.inv_mass[i], iI = s.inv_inertia[i];
    s.vx[i] += h * (f.fx[i] + f.fast_fx[i]) * im;
    s.vy[i] += h * (f.fy[i] + f.fast_fy[i]) * im;
    s.vz[i] += h * (f.fz[i] + f.fast_fz[i]) * im;
    s.wx[i] += h * (f.tx[i] + f.fast_tx[i]) * iI;
    s.wy[i] += h * (f.ty[i] + f.fast_ty[i]) * iI;
    s.wz[i] += h * (f.tz[i] + f.fast_tz[i]) * iI;
  };
  int alarm = 0;
  for (int j = 1; j <= k; ++j)
  {
#pragma omp for schedule(static) nowait
    for (long n = 0; n < movers; ++n)
    {
      const std::size_t iu = U(S.movers[static_cast<std::size_t>(n)]);
      kick(iu);
      s.x[iu] += delta * s.vx[iu];
      s.y[iu] += delta * s.vy[iu];
      s.z[iu] += delta * s.vz[iu];
    }
    // The slow partners on their straight drift (at the last substep exactly where it ends).
    const double back = (k - j) * delta;
#pragma omp for schedule(static) nowait
    for (long n = 0; n < dragged; ++n)
    {
      const std::size_t m = static_cast<std::size_t>(n), d = U(S.dragged[m]);
      s.x[d] = S.end_x[m] - back * s.vx[d];
      s.y[d] = S.end_y[m] - back * s.vy[d];
      s.z[d] = S.end_z[m] - back * s.vz[d];
    }
    // (fast_forces starts with the pairs, which read every position: its barrier comes after
    // them, so the positions must be complete first.)
#pragma omp barrier
    alarm |= fast_forces(delta, mine); // (ends with a barrier)
#pragma omp for schedule(static)
    for (long n = 0; n < movers; ++n)
      kick(U(S.movers[static_cast<std::size_t>(n)]));
  }
  const double inv_k = 1.0 / k;
#pragma omp for schedule(static) nowait
  for (long n = 0; n < dragged; ++n)
  {
    const std::size_t m = static_cast<std::size_t>(n), d = U(S.dragged[m]);
    s.x[d] = S.end_x[m];
    s.y[d] = S.end_y[m];
    s.z[d] = S.end_z[m];
    // The reaction summed over the substeps, as an average force over the step.
    f.fast_fx[d] *= inv_k;
    f.fast_fy[d] *= inv_k;
    f.fast_fz[d] *= inv_k;
    f.fast_tx[d] *= inv_k;
    f.fast_ty[d] *= inv_k;
    f.fast_tz[d] *= inv_k;
  }
  mine.overlap_alarm |= alarm;
  // This step's largest move (the held force terms renew by it) and the fast particles' state.
  double step2 = 0.0;
#pragma omp for schedule(static) nowait
  for (long n = 0; n < movers; ++n)
  {
    const std::size_t m = static_cast<std::size_t>(n), i = U(S.movers[m]);
    const double dx = s.x[i] - S.start_x[m], dy = s.y[i] - S.start_y[m], dz = s.z[i] - S.start_z[m];
    step2 = std::max(step2, dx * dx + dy * dy + dz * dz);
    if (!std::isfinite(s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i] + s.x[i] + s.y[i] + s.z[i]) &&
        mine.not_finite.particle < 0)
      mine.not_finite.set(static_cast<long>(i), s.position(i));
  }
  mine.max_step2 = std::max(mine.max_step2, step2);
  copy_fast_history(true); // (ends with a barrier)
}

// The slow particles' fast reaction (the average over the step's substeps) joins their
// forces before the final kick. Static share: the threads own the particles they own in the
// wall and column phases.
void DemSystem::add_fast_reaction_phase()
{
  const long n = static_cast<long>(particles_.size());
  const ParticleState &s = particles_;
  ForceBuffers &f = forces_;
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    if (substeps_.fast(s.species[i]))
      continue;
    f.add_fast_to_main(i);
  }
}

} // namespace magbrush::dem
