// Small scenes built in code for the DEM tests (no case files, no parser).
#pragma once

#include "dem/dem_system.h"

#include "coupling/case_model.h"

#include <cmath>
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

} // namespace magbrush::dem::testing
