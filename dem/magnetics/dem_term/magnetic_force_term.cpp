#include "magnetic_force_term.h"

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
  : dipoles_(with_slab_tail(settings, box, slab_tail), box), field_(field)
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
  for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    v->assign(n, 0.0);
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
  const std::size_t n = carrier_.size();
  if (n == 0)
    return;
  for (std::size_t k = 0; k < n; ++k)
  {
    x_[k] = state.x[carrier_[k]];
    y_[k] = state.y[carrier_[k]];
    z_[k] = state.z[carrier_[k]];
  }
  const BeadArrays beads{n, x_.data(), y_.data(), z_.data(), radius_.data(), mu_r_.data(), Ms_.data()};
  if (must_refresh_ || dipoles_.needs_refresh(beads, t))
  {
    for (auto *v : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
      std::fill(v->begin(), v->end(), 0.0);
    const AppliedMagneticField &field = field_;
    const AppliedFieldFunction lookup = [&field, t](const double x[3], double B[3], double g[3][3]) {
      Vec3 Bv;
      std::array<Vec3, 3> G;
      field.evaluate({x[0], x[1], x[2]}, t, Bv, G);
      for (int a = 0; a < 3; ++a)
      {
        B[a] = Bv[a];
        for (int b = 0; b < 3; ++b)
          g[a][b] = G[a][b];
      }
    };
    stats_ = dipoles_.compute(beads, lookup, t,
                              {fx_.data(), fy_.data(), fz_.data(), tx_.data(), ty_.data(), tz_.data()});
    ++evaluations_;
    must_refresh_ = false;
  }
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::size_t i = carrier_[k];
    forces.fx[i] += fx_[k];
    forces.fy[i] += fy_[k];
    forces.fz[i] += fz_[k];
    forces.tx[i] += tx_[k];
    forces.ty[i] += ty_[k];
    forces.tz[i] += tz_[k];
  }
}

void MagneticForceTerm::particles_reordered(const std::vector<std::int32_t> &order)
{
  // Map the compact carrier order through the engine's permutation, so that the kept dipoles
  // (the warm start), the held forces and the staleness reference follow their beads.
  std::vector<std::int32_t> compact_of_full(order.size(), -1);
  for (std::size_t k = 0; k < carrier_.size(); ++k)
    compact_of_full[carrier_[k]] = static_cast<std::int32_t>(k);
  std::vector<std::int32_t> compact_order;
  std::vector<std::uint32_t> new_carrier;
  for (std::size_t k = 0; k < order.size(); ++k)
  {
    const std::int32_t old_compact = compact_of_full[static_cast<std::size_t>(order[k])];
    if (old_compact >= 0)
    {
      compact_order.push_back(old_compact);
      new_carrier.push_back(static_cast<std::uint32_t>(k));
    }
  }
  if (compact_order.size() == carrier_.size())
  {
    dipoles_.particles_reordered(compact_order);
    // The held forces follow their beads too: a re-sort is no reason to re-evaluate (the
    // staleness check still sees how far every bead moved since the last evaluation).
    for (auto *v : {&radius_, &mu_r_, &Ms_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_})
    {
      const std::vector<double> old(*v);
      for (std::size_t k = 0; k < compact_order.size(); ++k)
        (*v)[k] = old[compact_order[k]];
    }
    carrier_ = new_carrier;
  }
  else
  {
    dipoles_.reset_dipoles();
    must_refresh_ = true;
  }
}

} // namespace magbrush::magnetics
