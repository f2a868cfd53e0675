// Small scenes built in code for the DEM tests (no case files, no parser).
#pragma once

#include "dem/dem_system.h"

#include "case/case_model.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>
#include <string>

namespace magbrush::dem::testing {

inline Material elastic_material(const std::string &name, double E, double nu, double rho)
{
  Material m;
  m.name = name;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.density = rho;
  m.friction = 0.0;
  m.damping = 0.0;
  m.restitution = -1.0;
  return m;
}

// A case with one particle population of `material` and no walls, no gravity.
inline Case single_species_case(const Material &m)
{
  Case c;
  c.name = "test";
  c.source_file = "(test)";
  c.scene = "box";
  c.materials.push_back(m);
  Population p;
  p.name = "spheres";
  p.material = m.name;
  p.diameter_mean = 1e-3;
  p.count = 0;
  c.populations.push_back(p);
  c.dem.gravity = {0.0, 0.0, 0.0};
  c.dem.air_viscosity = 0.0;
  return c;
}

// Adds a rigid plane wall (E huge) through `point` with `normal` into the particle side.
inline void add_rigid_plane(Case &c, const Vec3 &point, const Vec3 &normal, double nu = 0.3,
                            double friction = 0.0, const std::string &material = "wall")
{
  bool have = false;
  for (const auto &m : c.materials)
    have = have || m.name == material;
  if (!have)
  {
    Material w = elastic_material(material, 1e30, nu, 0.0);
    w.friction = friction;
    c.materials.push_back(w);
  }
  PlaneWall p;
  p.name = "plane";
  p.point = point;
  p.normal = normal;
  p.material = material;
  c.planes.push_back(p);
}

// Hertz closed forms (Chung & Ooi 2011, Johnson): maximum overlap, force, contact duration.
struct HertzImpact
{
  double delta_max, force_max, duration;
};
inline HertzImpact hertz_impact(double m_star, double R_star, double E_star, double v)
{
  HertzImpact h;
  h.delta_max = std::pow(15.0 * m_star * v * v / (16.0 * E_star * std::sqrt(R_star)), 0.4);
  h.force_max = 4.0 / 3.0 * E_star * std::sqrt(R_star) * std::pow(h.delta_max, 1.5);
  // t_c = 2 δmax / v ∫₀¹ dx / √(1 − x^{5/2}) = 2 δmax / v · (2/5) B(2/5, 1/2), exactly; the
  // often quoted 2.868 (m*²/(R* E*² v))^{1/5} rounds this at 1e-4, too coarse for the check.
  const double integral = 0.4 * std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
  h.duration = 2.0 * integral * h.delta_max / v;
  return h;
}

// Frictional, rolling-resistant, damped spheres (100 µm ± 10 %) inserted in a layer `height`
// thick over a rigid stage, in a periodic x–y box of side `side`, under gravity: with random
// initial velocities (give_random_velocities) every code path — contacts, wall contacts,
// list rebuilds, re-sorting — is exercised within a few hundred steps.
inline Case falling_spheres_case(long count, double side, double height, unsigned long seed)
{
  Material m = elastic_material("carrier", 1e8, 0.35, 2200);
  m.friction = 0.45;
  m.polygon_angles = 12;
  m.damping = 0.6;
  Case c = single_species_case(m);
  c.populations[0].diameter_mean = 100e-6;
  c.populations[0].diameter_std = 10e-6;
  c.populations[0].count = count;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{side, side, height}};
  c.dem.periodic_length_x = c.dem.periodic_length_y = side;
  c.dem.gravity = {0, 0, -9.81};
  c.dem.seed = seed;
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1}, 0.3, 0.35);
  c.materials.back().youngs_modulus = 5e10;
  return c;
}

// Random velocities in [−1, 1]³ m/s from a seeded stream.
inline void give_random_velocities(ParticleState &p, unsigned long seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    p.vx[i] = u(rng);
    p.vy[i] = u(rng);
    p.vz[i] = u(rng);
  }
}

// A sleeve's magnet stood in for by a pull of `g` [m/s²] towards the roller axis (z) on every
// particle: beads ride a conveyor sleeve by friction without the magnetics' cost.
class RadialPull : public ForceTerm
{
public:
  explicit RadialPull(double g) : g_(g) {}
  const char *name() const override { return "radial pull"; }
  void add_forces(const ParticleState &s, ForceBuffers &f, double) override
  {
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      const double r = std::hypot(s.x[i], s.y[i]);
      f.fx[i] -= g_ * s.mass[i] * s.x[i] / r;
      f.fy[i] -= g_ * s.mass[i] * s.y[i] / r;
    }
  }

private:
  double g_;
};

// The id and every dynamic quantity of each particle, in ascending id: id, x, y, z, v, ω,
// force, torque (state_values_per_particle numbers each, the force at state_force_offset).
constexpr std::size_t state_values_per_particle = 16;
constexpr std::size_t state_force_offset = 10;
inline std::vector<double> state_by_id(const DemSystem &s)
{
  const auto &p = s.particles();
  const auto &f = s.forces();
  std::vector<std::size_t> order(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(), [&p](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  std::vector<double> out;
  out.reserve(p.size() * state_values_per_particle);
  for (std::size_t i : order)
    for (double v : {static_cast<double>(p.id[i]), p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i], p.wx[i], p.wy[i],
                     p.wz[i], f.fx[i], f.fy[i], f.fz[i], f.tx[i], f.ty[i], f.tz[i]})
      out.push_back(v);
  return out;
}

inline bool bit_identical(const std::vector<double> &a, const std::vector<double> &b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

} // namespace magbrush::dem::testing
