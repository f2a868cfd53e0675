// Structure-of-arrays particle storage (see particle_state.h).
#include "dem/particle_state.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

void ParticleState::resize(std::size_t n)
{
  for (auto *a : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass,
                  &inv_inertia, &charge, &carried_mass, &carried_charge})
    a->resize(n, 0.0);
  carried_count.resize(n, 0);
  species.resize(n, 0);
  id.resize(n, 0);
}

void ParticleState::add(const Vector3 &p, double r, double density, int species_index,
                        double charge_value)
{
  const double m = density * 4.0 / 3.0 * M_PI * r * r * r;
  x.push_back(p.x);
  y.push_back(p.y);
  z.push_back(p.z);
  for (auto *a : {&vx, &vy, &vz, &wx, &wy, &wz})
    a->push_back(0.0);
  radius.push_back(r);
  mass.push_back(m);
  inv_mass.push_back(1.0 / m);
  inv_inertia.push_back(1.0 / (0.4 * m * r * r)); // solid sphere
  charge.push_back(charge_value);
  carried_count.push_back(0);
  carried_mass.push_back(0.0);
  carried_charge.push_back(0.0);
  species.push_back(species_index);
  id.push_back(next_id++);
}

void ParticleState::append_from(const ParticleState &o, std::size_t k)
{
  x.push_back(o.x[k]);
  y.push_back(o.y[k]);
  z.push_back(o.z[k]);
  vx.push_back(o.vx[k]);
  vy.push_back(o.vy[k]);
  vz.push_back(o.vz[k]);
  wx.push_back(o.wx[k]);
  wy.push_back(o.wy[k]);
  wz.push_back(o.wz[k]);
  radius.push_back(o.radius[k]);
  mass.push_back(o.mass[k]);
  inv_mass.push_back(o.inv_mass[k]);
  inv_inertia.push_back(o.inv_inertia[k]);
  charge.push_back(o.charge[k]);
  carried_count.push_back(o.carried_count[k]);
  carried_mass.push_back(o.carried_mass[k]);
  carried_charge.push_back(o.carried_charge[k]);
  species.push_back(o.species[k]);
  id.push_back(next_id++);
}

std::int32_t ParticleState::id_bound() const
{
  std::int32_t m = -1;
  for (std::int32_t v : id)
    m = std::max(m, v);
  return m + 1;
}

void ParticleState::permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
                            std::vector<std::int32_t> &iscratch)
{
  for (auto *a : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass,
                  &inv_inertia, &charge, &carried_mass, &carried_charge})
    permute_array(*a, order, scratch);
  permute_array(carried_count, order, iscratch);
  permute_array(species, order, iscratch);
  permute_array(id, order, iscratch);
}

void ForceBuffers::resize(std::size_t n)
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz, &fast_fx, &fast_fy, &fast_fz, &fast_tx, &fast_ty, &fast_tz})
    a->assign(n, 0.0);
}

void ForceBuffers::extend(std::size_t n)
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz, &fast_fx, &fast_fy, &fast_fz, &fast_tx, &fast_ty, &fast_tz})
    a->resize(n, 0.0);
}

void ForceBuffers::clear()
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz, &fast_fx, &fast_fy, &fast_fz, &fast_tx, &fast_ty, &fast_tz})
    std::fill(a->begin(), a->end(), 0.0);
}

void ForceBuffers::zero_fast()
{
  for (auto *a : {&fast_fx, &fast_fy, &fast_fz, &fast_tx, &fast_ty, &fast_tz})
    a->assign(fx.size(), 0.0);
}

void ForceBuffers::permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch)
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz, &fast_fx, &fast_fy, &fast_fz, &fast_tx, &fast_ty, &fast_tz})
    permute_array(*a, order, scratch);
}

} // namespace magbrush::dem
