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
}

// The fast pairs' history and touching flags between the list's slots (where the rebuild,
// the checkpoint and the diagnostics find them) and the substeps' compact copy.
void DemSystem::copy_fast_history(bool into_list)
{
  TonerSubsteps &S = substeps_;
  for (std::size_t q = 0; q < S.pair.size(); ++q)
  {
    const std::size_t p = U(S.pair[q]);
    double *list[3] = {&list_.hist_x[p], &list_.hist_y[p], &list_.hist_z[p]};
    double *compact[3] = {&S.hx[q], &S.hy[q], &S.hz[q]};
    for (int d = 0; d < 3; ++d)
      (into_list ? *list[d] : *compact[d]) = (into_list ? *compact[d] : *list[d]);
    (into_list ? list_.touching[p] : S.touching[q]) = (into_list ? S.touching[q] : list_.touching[p]);
  }
}

// The fast contacts at the current positions, with step dt (the history advances by dt): the
// fast particles' force and torque from zero into forces_.fast_*, the fast pairs first (in
// pair order), then each one's walls; with `react`, the slow members' reaction added to
// theirs. Returns 1 when a fast pair overlaps beyond the guard.
int DemSystem::fast_forces(double dt, StepFlags &mine, bool react)
{
  TonerSubsteps &S = substeps_;
  ParticleState &s = particles_;
  ForceBuffers &f = forces_;
  for (const std::int32_t i : S.movers)
  {
    const std::size_t iu = U(i);
    f.fast().zero(iu);
  }
  int alarm = 0;
  const std::size_t m = S.pair.size();
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
    const RowTorques T{S.tix.data(), S.tiy.data(), S.tiz.data()};
    alarm = particle_pair_kernel(D, T, 0, static_cast<std::int64_t>(m));
    const ForceArrays fast = f.fast();
    for (std::size_t q = 0; q < m; ++q)
    {
      const std::size_t i = U(S.owner[q]), j = U(S.partner[q]);
      const double on_i[3] = {S.fx[q], S.fy[q], S.fz[q]}, torque_i[3] = {S.tix[q], S.tiy[q], S.tiz[q]};
      const double on_j[3] = {-S.fx[q], -S.fy[q], -S.fz[q]}, torque_j[3] = {S.tjx[q], S.tjy[q], S.tjz[q]};
      if (react || S.fast(s.species[i]))
        fast.add(i, on_i, torque_i);
      if (react || S.fast(s.species[j]))
        fast.add(j, on_j, torque_j);
    }
  }
  if (walls_.size() > 0)
  {
    long wall_alarm = -1, too_many = -1;
    const ForceArrays fast = f.fast();
    for (const std::int32_t i : S.movers)
      particle_wall_contacts(U(i), dt, fast, wall_alarm, too_many);
    record_wall_alarms(mine, wall_alarm, too_many);
  }
  return alarm;
}

// The forces at the start, before the first step: the fast contacts as the slow ones (the
// history advances by one substep, as every pair's does by one step), the slow members'
// reaction added to their forces at once.
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
  mine.overlap_alarm |= fast_forces(S.substep, mine, true);
  copy_fast_history(true);
  for (const std::int32_t d : S.dragged)
  {
    const std::size_t du = U(d);
    f.add_fast_to_main(du);
  }
}

// One step's substeps (toner_substeps.h, item 3). Every thread of the team calls it; one
// does the work, and the others wait at the end (the slow pass needs the fast pairs' history
// back in the list, and the held terms need this step's largest move).
void DemSystem::toner_substeps_phase(StepFlags &mine)
{
#pragma omp single
  {
    TonerSubsteps &S = substeps_;
    ParticleState &s = particles_;
    ForceBuffers &f = forces_;
    const int k = S.substeps;
    const double delta = S.substep, h = 0.5 * delta;
    // The slow partners: where their drift ends, and their reaction from zero.
    for (std::size_t n = 0; n < S.dragged.size(); ++n)
    {
      const std::size_t d = U(S.dragged[n]);
      S.end_x[n] = s.x[d];
      S.end_y[n] = s.y[d];
      S.end_z[n] = s.z[d];
      f.fast().zero(d);
    }
    for (std::size_t n = 0; n < S.movers.size(); ++n)
    {
      const std::size_t i = U(S.movers[n]);
      S.start_x[n] = s.x[i];
      S.start_y[n] = s.y[i];
      S.start_z[n] = s.z[i];
    }
    copy_fast_history(false);
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
      for (const std::int32_t i : S.movers)
      {
        const std::size_t iu = U(i);
        kick(iu);
        s.x[iu] += delta * s.vx[iu];
        s.y[iu] += delta * s.vy[iu];
        s.z[iu] += delta * s.vz[iu];
      }
      // The slow partners on their straight drift (at the last substep exactly where it ends).
      const double back = (k - j) * delta;
      for (std::size_t n = 0; n < S.dragged.size(); ++n)
      {
        const std::size_t d = U(S.dragged[n]);
        s.x[d] = S.end_x[n] - back * s.vx[d];
        s.y[d] = S.end_y[n] - back * s.vy[d];
        s.z[d] = S.end_z[n] - back * s.vz[d];
      }
      alarm |= fast_forces(delta, mine, true);
      for (const std::int32_t i : S.movers)
        kick(U(i));
    }
    for (std::size_t n = 0; n < S.dragged.size(); ++n)
    {
      const std::size_t d = U(S.dragged[n]);
      s.x[d] = S.end_x[n];
      s.y[d] = S.end_y[n];
      s.z[d] = S.end_z[n];
      // The reaction summed over the substeps, as an average force over the step.
      const double inv_k = 1.0 / k;
      f.fast_fx[d] *= inv_k;
      f.fast_fy[d] *= inv_k;
      f.fast_fz[d] *= inv_k;
      f.fast_tx[d] *= inv_k;
      f.fast_ty[d] *= inv_k;
      f.fast_tz[d] *= inv_k;
    }
    copy_fast_history(true);
    mine.overlap_alarm |= alarm;
    // This step's largest move (the held force terms renew by it) and the fast particles' state.
    double step2 = 0.0;
    for (std::size_t n = 0; n < S.movers.size(); ++n)
    {
      const std::size_t i = U(S.movers[n]);
      const double dx = s.x[i] - S.start_x[n], dy = s.y[i] - S.start_y[n], dz = s.z[i] - S.start_z[n];
      step2 = std::max(step2, dx * dx + dy * dy + dz * dz);
      if (!std::isfinite(s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i] + s.x[i] + s.y[i] + s.z[i]) &&
          mine.not_finite.particle < 0)
        mine.not_finite.set(static_cast<long>(i), s.position(i));
    }
    mine.max_step2 = std::max(mine.max_step2, step2);
  }
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
