#include "dem/force_terms/magnetic_force_term.h"

#include "dem/particle_state.h"
#include "dem/periodic_unwrap.h"
#include "magnetics/dipole_physics.h"

#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"

#include "fields/field_files.h"

#include <numeric>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

namespace {
constexpr double no_change[3] = {0.0, 0.0, 0.0}; // (no live pair changes: hold_dipoles off)

MagneticSettings with_slab_tail(MagneticSettings s, const std::array<double, 3> &box, bool slab_tail)
{
  const int periodic = (box[0] > 0) + (box[1] > 0) + (box[2] > 0);
  // The slab tail corrects a hard cutoff; the cell-multipole far field has none.
  if (slab_tail && periodic == 2 && s.far_field == FarField::none)
    s.slab_tail_correction = true;
  return s;
}
} // namespace

MagneticForceTerm::MagneticForceTerm(const Case &c, MagneticSettings settings,
                                     const AppliedMagneticField &field,
                                     const std::array<double, 3> &box, bool slab_tail)
  : dipoles_(with_slab_tail(settings, box, slab_tail), box), field_(field), box_(box),
    waiting_correction_(dipoles_.settings(), box)
{
  for (const Population &pop : c.populations)
  {
    Species s;
    s.carrier = pop.kind == ParticleKind::carrier;
    if (s.carrier)
    {
      const Material &m = c.material(pop.material);
      s.mu_r = m.mu_r;
      s.saturation_magnetisation = m.saturation_magnetisation;
      carrier_beta_.push_back(clausius_mossotti(m.mu_r));
    }
    species_.push_back(s);
  }
  // The waiting carriers' correction tables are prepared when the first one waits: by then the
  // solver has tabulated the same β at its first evaluation, and a μr it cannot tabulate has
  // stopped the run there, in initialize(), with the key named.
}

void MagneticForceTerm::select_carriers(const dem::ParticleState &state)
{
  carrier_.clear();
  radius_.clear();
  mu_r_.clear();
  Ms_.clear();
  for (std::size_t k = 0; k < state.size(); ++k)
  {
    const std::size_t species = static_cast<std::size_t>(state.species[k]);
    if (species >= species_.size())
      throw std::runtime_error("magnetics: particle " + std::to_string(state.id[k]) +
                               " has population index " + std::to_string(species) +
                               ", but the case has " + std::to_string(species_.size()) +
                               " populations.");
    if (!species_[species].carrier)
      continue;
    carrier_.push_back(static_cast<std::uint32_t>(k));
    radius_.push_back(state.radius[k]);
    mu_r_.push_back(species_[species].mu_r);
    Ms_.push_back(species_[species].saturation_magnetisation);
  }
  state_size_ = state.size();
  const std::size_t n = carrier_.size();
  x_.resize(n);
  y_.resize(n);
  z_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    x_[k] = state.x[carrier_[k]];
    y_[k] = state.y[carrier_[k]];
    z_[k] = state.z[carrier_[k]];
  }
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    v->assign(n, 0.0);
  dipoles_.reset_dipoles();
  newcomers_.clear();
  left_ = 0;
  holes_ = 0;
  pending_ = false;
}

void MagneticForceTerm::gather_positions(const dem::ParticleState &state)
{
  // Each carrier keeps the image of its engine position nearest to its last one
  // (dem/periodic_unwrap.h); the carriers that left keep their last position. Shared with
  // `omp for` by the threads of the calling team, or run by one thread outside a team.
  const std::vector<double> *engine[3] = {&state.x, &state.y, &state.z};
  std::vector<double> *const mine[3] = {&x_, &y_, &z_};
#pragma omp for schedule(static)
  for (long kl = 0; kl < static_cast<long>(carrier_.size()); ++kl)
  {
    const auto k = static_cast<std::size_t>(kl);
    if (carrier_[k] == kLeft)
      continue;
    for (int d = 0; d < 3; ++d)
      (*mine[d])[k] = dem::nearest_image((*engine[d])[carrier_[k]], (*mine[d])[k], box_[static_cast<std::size_t>(d)]);
  }
}

BeadArrays MagneticForceTerm::bead_arrays() const
{
  return {carrier_.size(), x_.data(), y_.data(), z_.data(), radius_.data(), mu_r_.data(), Ms_.data()};
}

AppliedFieldFunction MagneticForceTerm::lookup_at(double t) const
{
  // The field is looked up at the engine's image of the (unwrapped) position.
  const AppliedMagneticField &field = field_;
  const std::array<double, 3> box = box_;
  return [&field, t, box](const double x[3], double B[3], double g[3][3]) {
    Vec3 X{x[0], x[1], x[2]};
    for (int d = 0; d < 3; ++d)
      if (box[d] > 0.0)
        X[d] -= box[d] * std::floor(X[d] / box[d]);
    Vec3 Bv;
    std::array<Vec3, 3> G;
    field.evaluate(X, t, Bv, G);
    for (int a = 0; a < 3; ++a)
    {
      B[a] = Bv[a];
      for (int b = 0; b < 3; ++b)
        g[a][b] = G[a][b];
    }
  };
}

void MagneticForceTerm::take_held_forces()
{
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    std::fill(v->begin(), v->end(), 0.0);
  dipoles_.add_held_forces({fx_.data(), fy_.data(), fz_.data(), tx_.data(), ty_.data(), tz_.data()});
}

void MagneticForceTerm::full_refresh(const BeadArrays &beads, double t, double ramp)
{
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    std::fill(v->begin(), v->end(), 0.0);
  const double t0 = omp_get_wtime();
  stats_ = dipoles_.compute(beads, lookup_at(t), t,
                            {fx_.data(), fy_.data(), fz_.data(), tx_.data(), ty_.data(), tz_.data()});
  const double spent = omp_get_wtime() - t0;
  counts_.full_s += spent;
  if (evaluations_ == 0)
    counts_.cold_s = spent;
  counts_.lists_s += stats_.time_lists;
  counts_.tensors_s += stats_.time_tensors;
  counts_.far_s += stats_.time_far;
  counts_.sweeps_s += stats_.time_sweeps;
  counts_.forces_s += stats_.time_forces;
  counts_.rebuilds += stats_.list_rebuilt;
  counts_.zero_field += stats_.zero_field;
  held_ramp_ = ramp;
  ++evaluations_;
}

std::string MagneticForceTerm::cost_note() const
{
  const RefreshCounts &c = counts_;
  char line[768];
  std::snprintf(line, sizeof line,
                "%ld full evaluations: %ld interval, %ld moved (lists expired %ld, region too large %ld), "
                "%ld first or new set; %ld list rebuilds; %ld local refreshes; %ld admissions. "
                "Time: full %.3g s (lists %.2g, tensors %.2g, far field %.2g, sweeps %.2g, forces %.2g), "
                "local %.3g s, admissions %.3g s, live pairs %.3g s, checks %.3g s; "
                "%ld of %ld steps held inside the engine's team (%ld of them quiet: no check needed; "
                "%ld with newcomers waiting)",
                c.first + c.interval + c.moved, c.interval, c.moved, c.moved_lists, c.moved_region, c.first,
                c.rebuilds, local_refreshes_, c.admitted, c.full_s, c.lists_s, c.tensors_s, c.far_s, c.sweeps_s,
                c.forces_s, c.local_s, c.admit_s, c.live_s, c.check_s, steps_in_team_, steps_, quiet_steps_,
                steps_in_team_waiting_);
  return line;
}

void MagneticForceTerm::add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces,
                                   double t)
{
  if (!enabled_)
    return;
  ++steps_;
  // A step outside the team is not in the engine's sum of drifts: the next team step looks.
  quiet_valid_ = false;
  if (quiet_moved_.size() < static_cast<std::size_t>(omp_get_max_threads()))
    quiet_moved_.resize(static_cast<std::size_t>(omp_get_max_threads()));
  // The team's held path may have gathered and checked this step already (and found that it
  // must evaluate): its verdict stands.
  const bool checked_in_team = checked_in_team_;
  checked_in_team_ = false;
  const bool set_changed = changed_ && !must_refresh_;
  if (must_refresh_ || state.size() != state_size_)
  {
    select_carriers(state);
    must_refresh_ = true;
  }
  else if (changed_)
  {
    admit_newcomers(state);
    must_refresh_ = true; // a full (warm-started) evaluation of the new set
  }
  changed_ = false;
  if (!pending_)
    newcomers_.clear();
  else if (carrier_.size() == left_ || newcomers_.size() > kMaxWaiting)
    apply_pending(state); // nothing held to wait with (the first carriers of an inflow), or
                          // so many newcomers that their per-step sums would cost more
  if (carrier_.empty())
    return;
  if (!checked_in_team)
    gather_positions(state);
  const double ramp = field_.ramp(t);
  const MagneticSettings &settings = dipoles_.settings();
  if (pending_ && !must_refresh_ && settings.admit_exchange && settings.far_field == FarField::cell_multipole &&
      ramp == held_ramp_)
    admit_pending(state, t);
  BeadArrays beads = bead_arrays();
  // A full evaluation is due: the exchanges held back since the last one join it first, and
  // so do the holes of admitted leavers when the lists are rebuilt anyway (or are many).
  auto full = [&]() {
    const bool holes = left_ > 0 && (8 * left_ > carrier_.size() || !dipoles_.lists_current(beads));
    if (pending_ || holes)
    {
      counts_.set_changed += pending_;
      apply_pending(state);
      beads = bead_arrays();
    }
    full_refresh(beads, t, ramp);
  };
  StalenessCheck check;
  if (must_refresh_)
    check.reason = RefreshReason::first;
  else if (checked_in_team)
    check = team_check_;
  else
  {
    const double t0 = omp_get_wtime();
    check = dipoles_.check_staleness(beads, t);
    counts_.check_s += omp_get_wtime() - t0;
  }
  // Held forces from a moment without field (before a ramp starts) cannot be rescaled: the
  // field has just come on, so evaluate.
  if (check.reason == RefreshReason::none && held_ramp_ == 0.0 && ramp > 0.0)
    check.reason = RefreshReason::first;
  switch (check.reason)
  {
  case RefreshReason::none:
    break;
  case RefreshReason::first:
  case RefreshReason::bead_count:
    ++counts_.first;
    counts_.set_changed += set_changed;
    full();
    break;
  case RefreshReason::interval:
    ++counts_.interval;
    full();
    break;
  case RefreshReason::moved:
  {
    bool local = false, tried = false;
    // (Saturating beads while the field ramps: the held state cannot be rescaled exactly.)
    if (dipoles_.settings().staleness_mode != StalenessMode::absolute && held_ramp_ > 0.0 &&
        (ramp == held_ramp_ || dipoles_.linear()))
    {
      // The held state at the current field strength first (exact for linear beads), then
      // the region around the moved beads.
      if (ramp != held_ramp_)
        dipoles_.scale_applied_field(ramp / held_ramp_);
      held_ramp_ = ramp;
      const double t0 = omp_get_wtime();
      tried = true;
      local = dipoles_.refresh_locally(beads, lookup_at(t), t, local_stats_);
      counts_.local_s += omp_get_wtime() - t0;
      counts_.region_beads += local ? static_cast<long>(local_stats_.local_region) : 0;
    }
    if (local)
    {
      ++local_refreshes_;
      take_held_forces();
    }
    else
    {
      ++counts_.moved;
      counts_.moved_lists += tried && dipoles_.local_fallback() == InducedDipoles::LocalFallback::lists;
      counts_.moved_region += tried && dipoles_.local_fallback() == InducedDipoles::LocalFallback::region;
      full();
    }
    break;
  }
  }
  must_refresh_ = false;
  // While the field ramps, the held forces follow it: F ∝ B² for linear beads. (Saturating
  // beads keep their forces until the next refresh.)
  const double scale = (held_ramp_ > 0.0 && ramp != held_ramp_ && dipoles_.linear())
                         ? (ramp / held_ramp_) * (ramp / held_ramp_) : 1.0;
  last_scale_ = scale;
  add_waiting_forces(state, forces, t);
  // Holding the dipoles: the close pairs' forces at the current positions (live_pairs.h).
  const std::vector<double> *live = nullptr;
  if (settings.hold_dipoles)
  {
    const double t0 = omp_get_wtime();
    live = dipoles_.live_pair_changes(bead_arrays());
    counts_.live_s += omp_get_wtime() - t0;
  }
  live_ = usable_live_changes(live);
  add_held_forces(forces, scale, live_);
}

// The steps that only hold: inside the engine's team, every thread sharing the same loops as
// add_forces() runs alone (gather, staleness check, close pairs, held forces), so the team
// need not stop and restart around the magnetics. A step that must evaluate, admit or follow a
// ramp goes to add_forces(), which takes over the check made here.
bool MagneticForceTerm::add_forces_in_team_if_held(const dem::ParticleState &state, dem::ForceBuffers &forces,
                                                   double t, double step_move)
{
  // (All of this is written outside the team only: every thread decides alike.)
  if (!held_steps_in_team_ || !enabled_ || carrier_.empty() || must_refresh_ || changed_ ||
      (!pending_ && !newcomers_.empty()) || state.size() != state_size_ || held_ramp_ == 0.0 ||
      field_.ramp(t) != held_ramp_)
    return false;
  // Newcomers that wait for a full evaluation (they entered empty space: admit_pending() would
  // keep them waiting) stay in the team; add_held_step() adds their forces as add_forces()
  // does. A step that could admit something or must apply the exchange goes out.
  if (pending_ && !waiting_stays_in_team(state))
    return false;
  // A quiet step: the last check (in the team) found nothing stale, and the engine's largest
  // drift per step, summed since, bounds every bead's move below the distance that check
  // certified (StalenessTracker::quiet_distance): every check until then would say "none",
  // so none is made and the positions are not even gathered. Each thread keeps its own copy
  // of the sum (the same on all); the flag is written outside the team or after a barrier.
  const auto me = static_cast<std::size_t>(omp_get_thread_num());
  // (quiet_team_ is recorded only by a team that fits quiet_moved_, so this also bounds me.)
  const bool tracked = quiet_valid_ && omp_get_num_threads() == quiet_team_;
  if (tracked && quiet_steps_on_)
  {
    const double moved = quiet_moved_[me].moved + step_move;
    if (moved < dipoles_.quiet_distance() && !dipoles_.interval_due(t))
    {
      quiet_moved_[me].moved = moved;
      if (pending_)
        gather_positions(state); // (the waiting forces read the held beads where they are)
      add_held_step(state, forces, t, false, pending_);
      return true;
    }
  }
  gather_positions(state);
  const BeadArrays beads = bead_arrays();
  const double t0 = omp_get_wtime();
  const StalenessCheck check = dipoles_.check_staleness(beads, t);
  const double t1 = omp_get_wtime();
#pragma omp master
  counts_.check_s += t1 - t0;
  if (check.reason != RefreshReason::none)
  {
#pragma omp master
    {
      team_check_ = check; // for add_forces(), after the team
      checked_in_team_ = true;
      quiet_valid_ = false;
    }
    return false;
  }
  // (Every thread read quiet_valid_ above, before the gather's barrier.)
  if (static_cast<std::size_t>(omp_get_num_threads()) <= quiet_moved_.size())
  {
    quiet_moved_[me].moved = 0.0;
#pragma omp master
    {
      quiet_valid_ = true;
      quiet_team_ = omp_get_num_threads();
    }
  }
  add_held_step(state, forces, t, true, true);
  return true;
}

bool MagneticForceTerm::waiting_stays_in_team(const dem::ParticleState &state) const
{
  // What add_forces() would do on this step besides the held forces: admit_pending() (only
  // with admit_exchange and the cell multipoles), apply_pending() (no held carrier to wait
  // with, or too many waiting), admitting the leavers as holes (left_ > holes_), a newcomer
  // in an occupied fine cell, dropping a waiting non-carrier, sorting the waiting list.
  // When none of that would happen, that step only adds the waiting and the held forces.
  const MagneticSettings &settings = dipoles_.settings();
  if (!settings.admit_exchange || settings.far_field != FarField::cell_multipole || left_ > holes_ ||
      carrier_.size() == left_ || newcomers_.empty() || newcomers_.size() > kMaxWaiting ||
      !std::is_sorted(newcomers_.begin(), newcomers_.end()))
    return false;
  for (const std::uint32_t i : newcomers_)
  {
    const std::size_t species = static_cast<std::size_t>(state.species[i]);
    if (species >= species_.size() || !species_[species].carrier)
      return false;
    const double x[3] = {state.x[i], state.y[i], state.z[i]};
    if (dipoles_.admissible_position(x))
      return false;
  }
  return true;
}

void MagneticForceTerm::add_held_step(const dem::ParticleState &state, dem::ForceBuffers &forces, double t,
                                      bool checked, bool gathered)
{
  // Called by every thread of the team, after a check (the positions gathered) or on a quiet
  // step (nothing looked at). The close pairs' changes read the positions only when they are
  // due: a quiet step gathers them then.
  const bool hold = dipoles_.settings().hold_dipoles;
  if (hold && !gathered && dipoles_.live_pair_changes_due())
    gather_positions(state);
  const BeadArrays beads = bead_arrays();
  const double t1 = omp_get_wtime();
  const std::vector<double> *live = hold ? usable_live_changes(dipoles_.live_pair_changes_in_team(beads)) : nullptr;
  const double t2 = omp_get_wtime();
#pragma omp master
  {
    counts_.live_s += t2 - t1;
    live_ = live;
    last_scale_ = 1.0;
    ++steps_in_team_;
    ++steps_;
    quiet_steps_ += checked ? 0 : 1;
    steps_in_team_waiting_ += pending_ ? 1 : 0;
  }
  // The waiting newcomers' forces come first, as in add_forces() (the same sums in the same
  // order); one thread: they add reactions to the held beads near each newcomer.
  if (pending_)
  {
#pragma omp single
    add_waiting_forces(state, forces, t);
  }
  add_held_forces(forces, 1.0, live);
}

const std::vector<double> *MagneticForceTerm::usable_live_changes(const std::vector<double> *live) const
{
  // (the held-back exchanges may just have joined: the changes must cover every bead)
  return live && live->size() == 3 * carrier_.size() ? live : nullptr;
}

void MagneticForceTerm::add_held_forces(dem::ForceBuffers &forces, double scale, const std::vector<double> *live)
{
  // Shared with `omp for` by the threads of the calling team, or one thread outside a team;
  // each carrier writes its own particle.
  const bool torque = dipoles_.settings().torque == TorqueModel::paper; // (otherwise no magnetic torque)
#pragma omp for schedule(static)
  for (long kl = 0; kl < static_cast<long>(carrier_.size()); ++kl)
  {
    const auto k = static_cast<std::size_t>(kl);
    const std::size_t i = carrier_[k];
    if (i == kLeft)
      continue;
    const double *dF = live ? &(*live)[3 * k] : no_change;
    forces.fx[i] += scale * (fx_[k] + dF[0]);
    forces.fy[i] += scale * (fy_[k] + dF[1]);
    forces.fz[i] += scale * (fz_[k] + dF[2]);
    if (torque)
    {
      forces.tx[i] += scale * tx_[k];
      forces.ty[i] += scale * ty_[k];
      forces.tz[i] += scale * tz_[k];
    }
  }
}

// MagneticSettings::admit_exchange: the exchanges since the last step join the held state
// without a full evaluation (InducedDipoles::admit). The carriers that left become inert
// holes in place (μr = 1, no saturation: no dipole, no force; still kLeft, at their last
// position) until a full evaluation that rebuilds the lists drops them (apply_pending); the
// carriers among the newcomers are appended, in ascending engine index. False when the
// magnetics cannot admit them now: everything is as before and they keep waiting.
bool MagneticForceTerm::admit_pending(const dem::ParticleState &state, double t)
{
  const std::size_t first = carrier_.size();
  leavers_.clear();
  leaver_mu_r_.clear();
  leaver_Ms_.clear();
  for (std::size_t k = 0; k < first; ++k)
    if (carrier_[k] == kLeft && mu_r_[k] != 1.0) // (a hole already has μr = 1)
    {
      leavers_.push_back(static_cast<std::uint32_t>(k));
      leaver_mu_r_.push_back(mu_r_[k]);
      leaver_Ms_.push_back(Ms_[k]);
      mu_r_[k] = 1.0;
      Ms_[k] = 0.0;
    }
  // The carriers among the newcomers that land in an occupied fine cell join now; the others
  // (entering empty space, e.g. above the pile: nobody near to get them wrong) keep waiting.
  std::sort(newcomers_.begin(), newcomers_.end());
  still_waiting_.clear();
  for (std::uint32_t i : newcomers_)
  {
    const std::size_t species = static_cast<std::size_t>(state.species[i]);
    if (species >= species_.size() || !species_[species].carrier)
      continue;
    const double x[3] = {state.x[i], state.y[i], state.z[i]};
    if (!dipoles_.admissible_position(x))
    {
      still_waiting_.push_back(i);
      continue;
    }
    append_bead(state, i, species_[species]);
  }
  if (leavers_.empty() && carrier_.size() == first) // (no carrier came or went that can join)
  {
    newcomers_.swap(still_waiting_);
    pending_ = !newcomers_.empty();
    return true;
  }
  const double t0 = omp_get_wtime();
  bool admitted = dipoles_.admit(bead_arrays(), first, leavers_, lookup_at(t), admit_stats_);
  bool leavers_only = false;
  if (!admitted && carrier_.size() > first && !leavers_.empty())
  {
    // The newcomers cannot join now (one is larger than every bead the two-sphere
    // correction's list was built for, or that list's reach with the skin comes to a period):
    // the leavers still can. Kept as frozen sources until the next full evaluation, they
    // would go on pulling at the beads they left (at an outflow: the front of the layer).
    for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
      v->resize(first);
    carrier_.resize(first);
    admitted = leavers_only = dipoles_.admit(bead_arrays(), first, leavers_, lookup_at(t), admit_stats_);
  }
  counts_.admit_s += omp_get_wtime() - t0;
  if (!admitted)
  {
    for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
      v->resize(first);
    carrier_.resize(first);
    for (std::size_t m = 0; m < leavers_.size(); ++m)
    {
      mu_r_[leavers_[m]] = leaver_mu_r_[m];
      Ms_[leavers_[m]] = leaver_Ms_[m];
    }
    return false;
  }
  ++counts_.admitted;
  holes_ += leavers_.size();
  counts_.admit_region_beads += static_cast<long>(admit_stats_.local_region);
  if (!leavers_only) // (otherwise every newcomer still waits)
    newcomers_.swap(still_waiting_);
  pending_ = !newcomers_.empty();
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    v->resize(carrier_.size());
  take_held_forces();
  return true;
}

// The carriers waiting for admission (defer_exchange), every step: each one's dipole induced
// by the applied field and the held dipoles of the beads within `reach` of it (one Jacobi
// step: the held dipoles do not answer it), its force (p·∇)B0 plus the point-dipole pair
// forces, and the reactions on those beads (Newton's third law). The two-sphere correction
// and the far field are left to the admission at the next full evaluation.
void MagneticForceTerm::add_waiting_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t)
{
  waiting_.clear();
  waiting_f_.clear();
  if (!pending_)
    return;
  if (dipoles_.settings().model == DipoleModel::corrected && !waiting_correction_.has_tables() && !carrier_beta_.empty())
    waiting_correction_.prepare_tables(carrier_beta_);
  const AppliedFieldFunction field = lookup_at(t);
  const std::vector<double> &held = dipoles_.dipoles();
  const std::size_t n = carrier_.size();
  const bool have_held = held.size() == 3 * n;
  // The held dipoles follow a ramping field (p ∝ B for linear beads).
  const double s = (held_ramp_ > 0.0 && dipoles_.linear()) ? field_.ramp(t) / held_ramp_ : 1.0;
  // The held beads that can be within reach of some newcomer: those inside the box around
  // all of them, grown by the largest reach (along the open axes; a periodic axis is not
  // cut). One pass over the held beads instead of one per newcomer; the candidates keep
  // ascending k, so every newcomer sums its neighbours in the same order as a full scan.
  candidates_.clear();
  if (have_held)
  {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (const std::uint32_t i : newcomers_)
    {
      const double x[3] = {state.x[i], state.y[i], state.z[i]}, reach = 8.0 * state.radius[i];
      for (int d = 0; d < 3; ++d)
        lo[d] = std::min(lo[d], x[d] - reach), hi[d] = std::max(hi[d], x[d] + reach);
    }
    for (int d = 0; d < 3; ++d)
      if (box_[d] > 0.0)
        lo[d] = -HUGE_VAL, hi[d] = HUGE_VAL;
    for (std::size_t k = 0; k < n; ++k)
      if (x_[k] >= lo[0] && x_[k] <= hi[0] && y_[k] >= lo[1] && y_[k] <= hi[1] && z_[k] >= lo[2] && z_[k] <= hi[2])
        candidates_.push_back(static_cast<std::uint32_t>(k));
  }
  for (const std::uint32_t i : newcomers_)
  {
    const std::size_t species = static_cast<std::size_t>(state.species[i]);
    if (species >= species_.size() || !species_[species].carrier)
      continue;
    const double x[3] = {state.x[i], state.y[i], state.z[i]};
    const double reach = 8.0 * state.radius[i]; // 4 diameters (the papers' cutoff)
    double B[3], g[3][3], p[3];
    field(x, B, g);
    neighbours_.clear();
    for (const std::uint32_t k : candidates_)
    {
      double r[3] = {x[0] - x_[k], x[1] - y_[k], x[2] - z_[k]};
      for (int d = 0; d < 3; ++d)
        if (box_[d] > 0.0)
          r[d] -= box_[d] * std::round(r[d] / box_[d]);
      const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      if (r2 >= reach * reach || r2 == 0.0)
        continue;
      const double pk[3] = {s * held[3 * k], s * held[3 * k + 1], s * held[3 * k + 2]};
      DipoleTensor::at(r).add_field(pk, B);
      neighbours_.push_back(static_cast<std::uint32_t>(k));
    }
    induced_moment(state.radius[i], clausius_mossotti(species_[species].mu_r),
                   species_[species].saturation_magnetisation, B, p);
    double F[3]; // (p·∇)B0: F_a = Σ_c p_c ∂B_a/∂x_c
    for (int a = 0; a < 3; ++a)
      F[a] = p[0] * g[a][0] + p[1] * g[a][1] + p[2] * g[a][2];
    for (const std::uint32_t k : neighbours_)
    {
      double r[3] = {x[0] - x_[k], x[1] - y_[k], x[2] - z_[k]};
      for (int d = 0; d < 3; ++d)
        if (box_[d] > 0.0)
          r[d] -= box_[d] * std::round(r[d] / box_[d]);
      const double pk[3] = {s * held[3 * k], s * held[3 * k + 1], s * held[3 * k + 2]};
      double Fp[3];
      dipole_pair_force(r, p, pk, Fp);
      if (dipoles_.settings().model == DipoleModel::corrected)
        add_waiting_correction(k, s, x, state.radius[i], clausius_mossotti(species_[species].mu_r), B, p, r, Fp);
      for (int d = 0; d < 3; ++d)
        F[d] += Fp[d];
      if (carrier_[k] == kLeft)
        continue;
      add_waiting(forces, carrier_[k], -Fp[0], -Fp[1], -Fp[2]);
    }
    add_waiting(forces, i, F[0], F[1], F[2]);
  }
}

// The two-sphere correction of the pair (held bead k, waiting bead at x), r = x − x_k, added
// to F (the force on the waiting bead): the held bead's local field gains the newcomer's
// field (the correction takes each partner's own contribution out again).
void MagneticForceTerm::add_waiting_correction(std::size_t k, double s, const double x[3], double radius,
                                               double beta, const double B[3], const double p[3],
                                               const double r[3], double F[3])
{
  (void)x;
  const std::vector<double> &held_p = dipoles_.dipoles();
  const std::vector<double> &held_B = dipoles_.local_fields();
  if (held_B.size() != held_p.size())
    return;
  const DipoleTensor T = DipoleTensor::at(r);
  pair_radius_[0] = radius_[k];
  pair_radius_[1] = radius;
  pair_beta_[0] = clausius_mossotti(mu_r_[k]);
  pair_beta_[1] = beta;
  double Bk[3] = {s * held_B[3 * k], s * held_B[3 * k + 1], s * held_B[3 * k + 2]};
  T.add_field(p, Bk);
  for (int d = 0; d < 3; ++d)
  {
    pair_field_[d] = Bk[d];
    pair_field_[3 + d] = B[d];
    pair_p_[d] = s * held_p[3 * k + d];
    pair_p_[3 + d] = p[d];
  }
  const double zero[2] = {0.0, 0.0};
  const BeadArrays pair{2, zero, zero, zero, pair_radius_.data(), zero, zero};
  waiting_correction_.add({pair, pair_beta_, pair_field_, pair_p_}, 0, 1, r, T, F);
}

void MagneticForceTerm::add_waiting(dem::ForceBuffers &forces, std::uint32_t i, double fx, double fy, double fz)
{
  forces.fx[i] += fx;
  forces.fy[i] += fy;
  forces.fz[i] += fz;
  waiting_.push_back(i);
  waiting_f_.push_back(fx);
  waiting_f_.push_back(fy);
  waiting_f_.push_back(fz);
}

void MagneticForceTerm::last_forces(std::vector<double> &fx, std::vector<double> &fy,
                                    std::vector<double> &fz) const
{
  fx.assign(state_size_, 0.0);
  fy.assign(state_size_, 0.0);
  fz.assign(state_size_, 0.0);
  for (std::size_t k = 0; k < carrier_.size(); ++k)
  {
    if (carrier_[k] == kLeft)
      continue;
    const double *dF = live_ && live_->size() == 3 * carrier_.size() ? &(*live_)[3 * k] : no_change;
    fx[carrier_[k]] = last_scale_ * (fx_[k] + dF[0]);
    fy[carrier_[k]] = last_scale_ * (fy_[k] + dF[1]);
    fz[carrier_[k]] = last_scale_ * (fz_[k] + dF[2]);
  }
  for (std::size_t w = 0; w < waiting_.size(); ++w)
  {
    fx[waiting_[w]] += waiting_f_[3 * w];
    fy[waiting_[w]] += waiting_f_[3 * w + 1];
    fz[waiting_[w]] += waiting_f_[3 * w + 2];
  }
}

void MagneticForceTerm::held_dipoles(std::vector<double> &p) const
{
  p.assign(3 * state_size_, 0.0);
  const std::vector<double> &held = dipoles_.dipoles();
  if (held.size() != 3 * carrier_.size())
    return; // nothing held yet
  for (std::size_t k = 0; k < carrier_.size(); ++k)
    if (carrier_[k] != kLeft)
      for (std::size_t d = 0; d < 3; ++d)
        p[3 * carrier_[k] + d] = std::sqrt(last_scale_) * held[3 * k + d]; // (p ∝ B, F ∝ B²)
}

void MagneticForceTerm::particles_reordered(const std::vector<std::int32_t> &order)
{
  // The engine re-sorted its arrays (new[k] = old[order[k]]): only the engine index of each
  // compact bead changes. The magnetics keep their own order, lists, dipoles and forces.
  if (carrier_.empty() && newcomers_.empty())
    return;
  if (order.size() != state_size_)
  {
    must_refresh_ = true;
    return;
  }
  std::vector<std::uint32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[static_cast<std::size_t>(order[k])] = static_cast<std::uint32_t>(k);
  for (auto &i : carrier_)
    if (i != kLeft)
      i = new_index[i];
  for (auto &i : newcomers_)
    i = new_index[i];
}

void MagneticForceTerm::particles_changed(const std::vector<std::int32_t> &origin)
{
  if (must_refresh_) // select_carriers() takes the whole set at the next step
  {
    state_size_ = origin.size();
    newcomers_.clear();
    return;
  }
  if (dipoles_.settings().defer_exchange && !changed_)
  {
    defer_change(origin);
    return;
  }
  // The compact beads whose particle left are dropped; the others keep their compact order.
  if (!follow_exchange(origin))
    return;
  // compact_origin_ maps the compact order to the one the dipole solver last saw.
  if (!changed_)
  {
    compact_origin_.resize(carrier_.size());
    for (std::size_t c = 0; c < carrier_.size(); ++c)
      compact_origin_[c] = static_cast<std::int32_t>(c);
  }
  std::size_t kept = 0;
  for (std::size_t c = 0; c < carrier_.size(); ++c)
  {
    const std::int32_t to = new_index_[carrier_[c]];
    if (to < 0)
      continue;
    carrier_[kept] = static_cast<std::uint32_t>(to);
    for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
      (*v)[kept] = (*v)[c];
    compact_origin_[kept] = compact_origin_[c];
    ++kept;
  }
  carrier_.resize(kept);
  compact_origin_.resize(kept);
  for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
    v->resize(kept);
  state_size_ = origin.size();
  changed_ = true;
}

// An exchange's map from the new engine index to the old (origin, −1: entered) turned around
// into new_index_ (old → new, −1: left), and the newcomers — those of an earlier change not
// yet admitted (two changes between steps), then this change's — renamed into the new order.
// False when the term has not seen this particle set: it selects afresh at the next step.
bool MagneticForceTerm::follow_exchange(const std::vector<std::int32_t> &origin)
{
  new_index_.assign(state_size_, -1);
  for (std::size_t k = 0; k < origin.size(); ++k)
    if (origin[k] >= 0)
    {
      if (static_cast<std::size_t>(origin[k]) >= state_size_)
      {
        must_refresh_ = true;
        state_size_ = origin.size();
        return false;
      }
      new_index_[static_cast<std::size_t>(origin[k])] = static_cast<std::int32_t>(k);
    }
  std::size_t still = 0;
  for (std::uint32_t i : newcomers_)
    if (new_index_[i] >= 0)
      newcomers_[still++] = static_cast<std::uint32_t>(new_index_[i]);
  newcomers_.resize(still);
  for (std::size_t k = 0; k < origin.size(); ++k)
    if (origin[k] < 0)
      newcomers_.push_back(static_cast<std::uint32_t>(k));
  return true;
}

// MagneticSettings::defer_exchange. An exchange changes only which engine index each compact
// bead reads: a bead whose particle left becomes a frozen source (kLeft), the newcomers are
// remembered (through re-sorts and further exchanges) until apply_pending(). An exchange
// that moved nothing in or out changes nothing at all.
void MagneticForceTerm::defer_change(const std::vector<std::int32_t> &origin)
{
  bool identity = origin.size() == state_size_;
  for (std::size_t k = 0; identity && k < origin.size(); ++k)
    identity = origin[k] == static_cast<std::int32_t>(k);
  if (identity)
    return;
  if (!follow_exchange(origin))
    return;
  for (auto &i : carrier_)
    if (i != kLeft)
    {
      const std::int32_t to = new_index_[i];
      left_ += to < 0;
      i = to < 0 ? kLeft : static_cast<std::uint32_t>(to);
    }
  state_size_ = origin.size();
  pending_ = left_ > holes_ || !newcomers_.empty();
}

// Before a full evaluation: the frozen sources go, the newcomers join (as particles_changed
// does at once without the deferral), the solver learns the new set.
void MagneticForceTerm::apply_pending(const dem::ParticleState &state)
{
  compact_origin_.resize(carrier_.size());
  std::size_t kept = 0;
  for (std::size_t c = 0; c < carrier_.size(); ++c)
  {
    if (carrier_[c] == kLeft)
      continue;
    carrier_[kept] = carrier_[c];
    for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
      (*v)[kept] = (*v)[c];
    compact_origin_[kept] = static_cast<std::int32_t>(c);
    ++kept;
  }
  carrier_.resize(kept);
  compact_origin_.resize(kept);
  for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
    v->resize(kept);
  left_ = 0;
  holes_ = 0;
  pending_ = false;
  admit_newcomers(state);
  newcomers_.clear();
}

// The carriers among the particles that entered, in ascending engine index, appended to the
// compact order; then the dipole solver learns the new set (kept dipoles as the initial guess).
void MagneticForceTerm::admit_newcomers(const dem::ParticleState &state)
{
  std::sort(newcomers_.begin(), newcomers_.end());
  for (std::uint32_t k : newcomers_)
  {
    const std::size_t species = static_cast<std::size_t>(state.species[k]);
    if (species >= species_.size() || !species_[species].carrier)
      continue;
    append_bead(state, k, species_[species]);
    compact_origin_.push_back(-1);
  }
  follow_engine_order();
  const std::size_t n = carrier_.size();
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    v->assign(n, 0.0);
  dipoles_.particles_changed(compact_origin_);
  compact_origin_.clear();
}

// The compact order re-sorted by engine index, while the solver learns a new set anyway (its
// lists are rebuilt for it). The engine keeps its particles in cell order (it re-sorts them at
// every list build), so this puts neighbours in space next to each other in the magnetics' own
// arrays too, and makes the per-step loops (positions gathered, held forces added: engine
// index carrier_[k] for compact bead k) read and write the engine's arrays as a stream instead
// of a scatter. Without it the order decays with every exchange (newcomers join at the end,
// the engine moves everyone else), and in a fed scene after a few thousand exchanges those
// loops wait on cache misses (docs/magnetics.md, "The fed nip's error budget, and the compact
// order following the engine's").
// compact_origin_ (new compact bead → the solver's old index) is permuted alongside.
void MagneticForceTerm::follow_engine_order()
{
  if (!follow_engine_order_on_ || std::is_sorted(carrier_.begin(), carrier_.end()))
    return;
  sort_order_.resize(carrier_.size());
  std::iota(sort_order_.begin(), sort_order_.end(), 0);
  const auto engine_index = [this](std::int32_t k) { return carrier_[static_cast<std::size_t>(k)]; };
  std::sort(sort_order_.begin(), sort_order_.end(),
            [&](std::int32_t a, std::int32_t b) { return engine_index(a) < engine_index(b); });
  for (auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_})
    dem::permute_array(*v, sort_order_, sort_scratch_);
  dem::permute_array(compact_origin_, sort_order_, sort_index_scratch_);
  dem::permute_array(carrier_, sort_order_, sort_carrier_scratch_);
}

// ---------------------------------------------------------------------------------------
// Checkpoint. The term's own state first, then the magnetics', in one block, so that a block
// written under other settings can be skipped whole.

void MagneticForceTerm::write_state(dem::CheckpointWriter &out) const
{
  MemoryStateOut block;
  block.put<std::uint64_t>(state_size_);
  block.put_array(carrier_);
  for (const auto *v : {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    block.put_array(*v);
  block.put<std::uint8_t>(must_refresh_);
  block.put(held_ramp_);
  block.put(last_scale_);
  block.put(evaluations_);
  block.put(local_refreshes_);
  block.put(static_cast<const RefreshCountsStored &>(counts_));
  block.put(stats_);
  block.put(local_stats_);
  dipoles_.write_state(block);
  // Appended later (a block without them, from before, reads as nothing pending): the
  // exchanges held back (defer_exchange) and the counters of the causes.
  block.put_array(newcomers_);
  block.put<std::uint8_t>(pending_);
  block.put(counts_.moved_lists);
  block.put(counts_.moved_region);
  block.put(counts_.set_changed);
  block.put(counts_.admitted); // (appended later again: a block without them reads as 0)
  block.put(counts_.admit_s);
  block.put(counts_.admit_region_beads);
  out.put_string(block.bytes());
}

void MagneticForceTerm::read_state(dem::CheckpointReader &in)
{
  MemoryStateIn block(in.get_string(), "checkpoint '" + in.path() + "', magnetic state,");
  restored_ = false;
  quiet_valid_ = false;
  const auto state_size = block.get<std::uint64_t>();
  std::vector<std::uint32_t> carrier;
  block.get_array(carrier);
  std::vector<double> v[12];
  for (auto &a : v)
    block.get_array(a);
  for (const auto &a : v)
    if (a.size() != carrier.size())
      block.fail("is corrupt (per-carrier arrays of different lengths)");
  std::size_t left = 0;
  for (const std::uint32_t i : carrier)
    if (i == kLeft)
      ++left;
    else if (i >= state_size)
      block.fail("is corrupt (a carrier index beyond the particle count)");
  const bool must_refresh = block.get<std::uint8_t>() != 0;
  const double held_ramp = block.get<double>(), last_scale = block.get<double>();
  const long evaluations = block.get<long>(), local_refreshes = block.get<long>();
  RefreshCounts counts;
  static_cast<RefreshCountsStored &>(counts) = block.get<RefreshCountsStored>();
  const auto stats = block.get<MagneticStats>(), local_stats = block.get<MagneticStats>();
  if (!dipoles_.read_state(block))
  {
    // Written under other magnetic settings (a restart that changes them on purpose): start
    // afresh at the next step, as a new run would.
    must_refresh_ = true;
    return;
  }
  std::vector<std::uint32_t> newcomers;
  bool pending = false;
  if (block.remaining() > 0)
  {
    block.get_array(newcomers);
    for (const std::uint32_t i : newcomers)
      if (i >= state_size)
        block.fail("is corrupt (a newcomer index beyond the particle count)");
    pending = block.get<std::uint8_t>() != 0;
    counts.moved_lists = block.get<long>();
    counts.moved_region = block.get<long>();
    counts.set_changed = block.get<long>();
  }
  if (block.remaining() > 0)
  {
    counts.admitted = block.get<long>();
    counts.admit_s = block.get<double>();
    counts.admit_region_beads = block.get<long>();
  }
  state_size_ = static_cast<std::size_t>(state_size);
  carrier_ = std::move(carrier);
  newcomers_ = std::move(newcomers);
  left_ = left;
  pending_ = pending;
  std::vector<double> *mine[12] = {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_};
  for (int k = 0; k < 12; ++k)
    *mine[k] = std::move(v[k]);
  holes_ = 0; // the admitted leavers (inert, μr = 1): only admit_exchange makes them
  if (dipoles_.settings().admit_exchange)
    for (std::size_t k = 0; k < carrier_.size(); ++k)
      holes_ += carrier_[k] == kLeft && mu_r_[k] == 1.0;
  must_refresh_ = must_refresh;
  held_ramp_ = held_ramp;
  last_scale_ = last_scale;
  evaluations_ = evaluations;
  local_refreshes_ = local_refreshes;
  counts_ = counts;
  stats_ = stats;
  local_stats_ = local_stats;
  restored_ = true;
}

namespace {
// The carriers' induced-dipole magnetics, when the scene has an applied field and carriers to
// feel it: a uniform (ramped) field needs no grid; a roller field is read from the stored
// magnetic grid, which must have been computed for this very case (`magbrush field`).
std::string magnetics_not_needed_because(const Case &c)
{
  if (c.applied_field.kind == AppliedField::Kind::none)
    return "the case has no applied field";
  // A zero field induces no dipoles: no solve, no grid read. (uniform_magnitude is the peak of
  // a schedule, so a schedule that is zero throughout is caught too.)
  if (c.applied_field.kind == AppliedField::Kind::uniform && c.applied_field.uniform_magnitude == 0.0)
    return "the applied uniform field is zero (applied_field.magnitude and every schedule value are 0 T)";
  if (c.applied_field.kind == AppliedField::Kind::roller && c.roller &&
      std::all_of(c.roller->poles.begin(), c.roller->poles.end(), [](const Pole &p) { return p.strength == 0.0; }))
    return "every pole of the roller has zero strength (the roller field is zero)";
  for (const auto &p : c.populations)
    if (p.kind == ParticleKind::carrier)
      return "";
  return "no carrier population";
}

std::unique_ptr<dem::ForceTerm> make_magnetics(const Case &c, const dem::DemSystem &system)
{
  const AppliedMagneticField field =
      c.applied_field.kind == AppliedField::Kind::roller
          ? AppliedMagneticField::for_case(c, field::magnetic_grid_path(c))
          : AppliedMagneticField::from_settings(c.applied_field);
  return std::make_unique<MagneticForceTerm>(c, MagneticSettings::from_case(c.dem), field,
                                             system.box().length);
}

const bool registered = dem::register_force_term({"magnetic dipoles", dem::force_term_order::magnetic_dipoles,
                                                  magnetics_not_needed_because, make_magnetics});
} // namespace

void MagneticForceTerm::append_bead(const dem::ParticleState &state, std::size_t i, const Species &species)
{
  carrier_.push_back(static_cast<std::uint32_t>(i));
  x_.push_back(state.x[i]);
  y_.push_back(state.y[i]);
  z_.push_back(state.z[i]);
  radius_.push_back(state.radius[i]);
  mu_r_.push_back(species.mu_r);
  Ms_.push_back(species.saturation_magnetisation);
}

} // namespace magbrush::magnetics
