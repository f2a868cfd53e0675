// Structure-of-arrays particle storage (see particle_state.h).
#include "dem/particle_state.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

void ParticleState::resize(std::size_t n)
{
  for (auto *a : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass,
                  &inv_inertia, &charge})
    a->resize(n, 0.0);
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
  species.push_back(species_index);
  id.push_back(static_cast<std::int32_t>(id.size()));
}

void ParticleState::permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
                            std::vector<std::int32_t> &iscratch)
{
  for (auto *a : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &radius, &mass, &inv_mass,
                  &inv_inertia, &charge})
    permute_array(*a, order, scratch);
  permute_array(species, order, iscratch);
  permute_array(id, order, iscratch);
}

void ForceBuffers::resize(std::size_t n)
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz})
    a->assign(n, 0.0);
}

void ForceBuffers::clear()
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz})
    std::fill(a->begin(), a->end(), 0.0);
}

void ForceBuffers::permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch)
{
  for (auto *a : {&fx, &fy, &fz, &tx, &ty, &tz})
    permute_array(*a, order, scratch);
}

} // namespace magbrush::dem
