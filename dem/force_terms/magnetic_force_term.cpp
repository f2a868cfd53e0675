#include "dem/force_terms/magnetic_force_term.h"

#include "dem/periodic_unwrap.h"

#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"

#include "coupling/field_files.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

namespace {
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
  : dipoles_(with_slab_tail(settings, box, slab_tail), box), field_(field), box_(box)
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
    }
    species_.push_back(s);
  }
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
}

void MagneticForceTerm::gather_positions(const dem::ParticleState &state)
{
  std::vector<double> *const mine[3] = {&x_, &y_, &z_};
  dem::follow_unwrapped(state, carrier_, box_, mine); // dem/periodic_unwrap.h
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

void MagneticForceTerm::add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces,
                                   double t)
{
  if (!enabled_)
    return;
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
  newcomers_.clear();
  const std::size_t n = carrier_.size();
  if (n == 0)
    return;
  gather_positions(state);
  const BeadArrays beads{n, x_.data(), y_.data(), z_.data(), radius_.data(), mu_r_.data(), Ms_.data()};
  const double ramp = field_.ramp(t);
  StalenessCheck check;
  if (must_refresh_)
    check.reason = RefreshReason::first;
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
    full_refresh(beads, t, ramp);
    break;
  case RefreshReason::interval:
    ++counts_.interval;
    full_refresh(beads, t, ramp);
    break;
  case RefreshReason::moved:
  {
    bool local = false;
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
      full_refresh(beads, t, ramp);
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
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::size_t i = carrier_[k];
    forces.fx[i] += scale * fx_[k];
    forces.fy[i] += scale * fy_[k];
    forces.fz[i] += scale * fz_[k];
  }
  if (dipoles_.settings().torque == TorqueModel::paper) // (otherwise no magnetic torque)
    for (std::size_t k = 0; k < n; ++k)
    {
      const std::size_t i = carrier_[k];
      forces.tx[i] += scale * tx_[k];
      forces.ty[i] += scale * ty_[k];
      forces.tz[i] += scale * tz_[k];
    }
}

void MagneticForceTerm::last_forces(std::vector<double> &fx, std::vector<double> &fy,
                                    std::vector<double> &fz) const
{
  fx.assign(state_size_, 0.0);
  fy.assign(state_size_, 0.0);
  fz.assign(state_size_, 0.0);
  for (std::size_t k = 0; k < carrier_.size(); ++k)
  {
    fx[carrier_[k]] = last_scale_ * fx_[k];
    fy[carrier_[k]] = last_scale_ * fy_[k];
    fz[carrier_[k]] = last_scale_ * fz_[k];
  }
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
    i = new_index[i];
  for (auto &i : newcomers_)
    i = new_index[i];
}

void MagneticForceTerm::particles_changed(const std::vector<std::int32_t> &origin)
{
  // Old engine index → new (−1: left). The compact beads whose particle left are dropped;
  // the others keep their compact order.
  new_index_.assign(state_size_, -1);
  for (std::size_t k = 0; k < origin.size(); ++k)
    if (origin[k] >= 0)
    {
      if (static_cast<std::size_t>(origin[k]) >= state_size_)
      { // the term has not seen this particle set: select afresh at the next step
        must_refresh_ = true;
        state_size_ = origin.size();
        return;
      }
      new_index_[static_cast<std::size_t>(origin[k])] = static_cast<std::int32_t>(k);
    }
  // Newcomers of an earlier change not yet admitted (two changes between steps) follow too.
  std::size_t still = 0;
  for (std::uint32_t i : newcomers_)
    if (new_index_[i] >= 0)
      newcomers_[still++] = static_cast<std::uint32_t>(new_index_[i]);
  newcomers_.resize(still);
  for (std::size_t k = 0; k < origin.size(); ++k)
    if (origin[k] < 0)
      newcomers_.push_back(static_cast<std::uint32_t>(k));
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
    carrier_.push_back(k);
    x_.push_back(state.x[k]);
    y_.push_back(state.y[k]);
    z_.push_back(state.z[k]);
    radius_.push_back(state.radius[k]);
    mu_r_.push_back(species_[species].mu_r);
    Ms_.push_back(species_[species].saturation_magnetisation);
    compact_origin_.push_back(-1);
  }
  const std::size_t n = carrier_.size();
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    v->assign(n, 0.0);
  dipoles_.particles_changed(compact_origin_);
  compact_origin_.clear();
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
  block.put(counts_);
  block.put(stats_);
  block.put(local_stats_);
  dipoles_.write_state(block);
  out.put_string(block.bytes());
}

void MagneticForceTerm::read_state(dem::CheckpointReader &in)
{
  MemoryStateIn block(in.get_string(), "checkpoint '" + in.path() + "', magnetic state,");
  restored_ = false;
  const auto state_size = block.get<std::uint64_t>();
  std::vector<std::uint32_t> carrier;
  block.get_array(carrier);
  std::vector<double> v[12];
  for (auto &a : v)
    block.get_array(a);
  for (const auto &a : v)
    if (a.size() != carrier.size())
      block.fail("is corrupt (per-carrier arrays of different lengths)");
  for (const std::uint32_t i : carrier)
    if (i >= state_size)
      block.fail("is corrupt (a carrier index beyond the particle count)");
  const bool must_refresh = block.get<std::uint8_t>() != 0;
  const double held_ramp = block.get<double>(), last_scale = block.get<double>();
  const long evaluations = block.get<long>(), local_refreshes = block.get<long>();
  const auto counts = block.get<RefreshCounts>();
  const auto stats = block.get<MagneticStats>(), local_stats = block.get<MagneticStats>();
  if (!dipoles_.read_state(block))
  {
    // Written under other magnetic settings (a restart that changes them on purpose): start
    // afresh at the next step, as a new run would.
    must_refresh_ = true;
    return;
  }
  state_size_ = static_cast<std::size_t>(state_size);
  carrier_ = std::move(carrier);
  std::vector<double> *mine[12] = {&x_, &y_, &z_, &radius_, &mu_r_, &Ms_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_};
  for (int k = 0; k < 12; ++k)
    *mine[k] = std::move(v[k]);
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

} // namespace magbrush::magnetics
