// Particle data as structure of arrays: one contiguous array per quantity, so that every
// kernel streams through exactly the data it needs and vectorises, and so that other units
// (the magnetics in magnetics/, future Coulomb/van der Waals terms) can work on plain
// arrays without knowing anything about the engine.
//
// Index order is NOT stable: the engine periodically re-sorts particles in cell order for
// cache locality. `id` is the stable name of a particle (0 .. N-1, dense).
#pragma once

#include "dem/vector3.h"

#include <cstdint>
#include <vector>

namespace magbrush::dem {

struct ParticleState
{
  // Kinematics [m, m/s, rad/s].
  std::vector<double> x, y, z;
  std::vector<double> vx, vy, vz;
  std::vector<double> wx, wy, wz;
  // Per-particle constants.
  std::vector<double> radius;      // [m]
  std::vector<double> mass;        // [kg]
  std::vector<double> inv_mass;    // [1/kg]
  std::vector<double> inv_inertia; // 1 / (2/5 m r²) [1/(kg m²)]
  std::vector<double> charge;      // [C]
  std::vector<std::int32_t> species; // population index in the case
  std::vector<std::int32_t> id;      // stable particle name

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n);

  Vector3 position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  Vector3 velocity(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
  Vector3 angular_velocity(std::size_t i) const { return {wx[i], wy[i], wz[i]}; }

  // Appends one sphere of the given radius and density at rest.
  void add(const Vector3 &p, double r, double density, int species_index, double charge_value);

  // Reorders every array: new[k] = old[order[k]]. `scratch` avoids allocation.
  void permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
               std::vector<std::int32_t> &iscratch);
};

// Forces and torques [N, N m] accumulated during one step. Force terms ADD to these.
struct ForceBuffers
{
  std::vector<double> fx, fy, fz;
  std::vector<double> tx, ty, tz;

  void resize(std::size_t n);
  void clear();
  void permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch);
};

// Reorders one array by `order` through `scratch` (new[k] = old[order[k]]).
template <typename T>
void permute_array(std::vector<T> &a, const std::vector<std::int32_t> &order, std::vector<T> &scratch)
{
  scratch.resize(a.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    scratch[k] = a[static_cast<std::size_t>(order[k])];
  a.swap(scratch);
}

} // namespace magbrush::dem
