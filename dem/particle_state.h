// Particle data as structure of arrays: one contiguous array per quantity, so that every
// kernel streams through exactly the data it needs and vectorises, and so that other units
// (the magnetics in magnetics/, future Coulomb/van der Waals terms) can work on plain
// arrays without knowing anything about the engine.
//
// Index order is NOT stable: the engine periodically re-sorts particles in cell order for
// cache locality. `id` is the stable name of a particle: given once, from the counter
// `next_id`, and never reused, so that after particles have entered and left a scene the ids
// are unique but NOT dense (nothing may index an array by id; sort or search by id instead).
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
  std::vector<double> charge;      // [C] (a carrier's includes the toner it carries)
  // Toner carried by a carrier as part of its mass and charge instead of as particles
  // (populations[].carried_until_gap, dem/carried_toner.h): how many toner, their mass and
  // their charge; zero for every other particle. `mass` and `charge` above include them.
  std::vector<std::int32_t> carried_count;
  std::vector<double> carried_mass;   // [kg]
  std::vector<double> carried_charge; // [C]
  std::vector<std::int32_t> species; // population index in the case
  std::vector<std::int32_t> id;      // stable particle name
  std::int32_t next_id = 0;          // the id the next added particle gets

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n);

  Vector3 position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  Vector3 velocity(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
  Vector3 angular_velocity(std::size_t i) const { return {wx[i], wy[i], wz[i]}; }

  // Appends one sphere of the given radius and density at rest.
  void add(const Vector3 &p, double r, double density, int species_index, double charge_value);

  // Appends particle k of `other` as it is (kinematics, constants, species, charge) under a
  // new id from next_id.
  void append_from(const ParticleState &other, std::size_t k);

  // Reorders every array: new[k] = old[order[k]]. `scratch` avoids allocation. `order` may
  // be shorter than the arrays: the particles it does not name are dropped.
  void permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
               std::vector<std::int32_t> &iscratch);

  // The largest id + 1 (0 when empty): next_id may not be lower than this.
  std::int32_t id_bound() const;
};

// Six per-particle arrays a contact adds its force and torque to (ForceBuffers::main / fast).
struct ForceArrays
{
  double *fx, *fy, *fz, *tx, *ty, *tz;
  void add(std::size_t i, const double f[3], const double t[3]) const
  {
    fx[i] += f[0];
    fy[i] += f[1];
    fz[i] += f[2];
    tx[i] += t[0];
    ty[i] += t[1];
    tz[i] += t[2];
  }
  void zero(std::size_t i) const { fx[i] = fy[i] = fz[i] = tx[i] = ty[i] = tz[i] = 0.0; }
};

// Forces and torques [N, N m] accumulated during one step. Force terms ADD to these.
struct ForceBuffers
{
  std::vector<double> fx, fy, fz;
  std::vector<double> tx, ty, tz;
  // With the toner in substeps (dem/toner_substeps.h), the contacts that take a subcycled
  // particle part, kept apart from the rest: on a subcycled particle, their force and torque
  // at its last substep (fx … hold the other forces, constant over the substeps); on any
  // other particle, their average over the last step (added to fx … before its final kick).
  // Zero, and unused, without substeps.
  std::vector<double> fast_fx, fast_fy, fast_fz;
  std::vector<double> fast_tx, fast_ty, fast_tz;

  ForceArrays main() { return {fx.data(), fy.data(), fz.data(), tx.data(), ty.data(), tz.data()}; }
  ForceArrays fast() { return {fast_fx.data(), fast_fy.data(), fast_fz.data(), fast_tx.data(), fast_ty.data(), fast_tz.data()}; }
  // Particle i's fast force and torque added to its force and torque.
  void add_fast_to_main(std::size_t i)
  {
    fx[i] += fast_fx[i];
    fy[i] += fast_fy[i];
    fz[i] += fast_fz[i];
    tx[i] += fast_tx[i];
    ty[i] += fast_ty[i];
    tz[i] += fast_tz[i];
  }

  void resize(std::size_t n);
  // Grows to n particles, the new ones at zero (the others keep their values).
  void extend(std::size_t n);
  void clear();
  // The fast arrays sized like fx and zeroed: for a buffer that never takes substeps (a held
  // term's store) after fx … were read or carried on their own.
  void zero_fast();
  void permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch);
};

// Reorders one array by `order` through `scratch` (new[k] = old[order[k]]); the result has
// order.size() elements (an order that leaves indices out drops those elements).
template <typename T>
void permute_array(std::vector<T> &a, const std::vector<std::int32_t> &order, std::vector<T> &scratch)
{
  scratch.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    scratch[k] = a[static_cast<std::size_t>(order[k])];
  a.swap(scratch);
}

} // namespace magbrush::dem
