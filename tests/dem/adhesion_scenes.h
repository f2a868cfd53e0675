// Scenes of the adhesion tests and of the toner time-step benchmark: a 7 µm toner with 50 nm
// asperities, a 50 µm carrier, a 50 GPa plate, a uniform field ramped from zero (a test-only
// force term), and the pull-off experiment built from them.
#pragma once

#include "tests/dem/dem_test_scenes.h"

#include "dem/dem_system.h"
#include "dem/force_term.h"

#include <omp.h>

#include <cmath>
#include <memory>

namespace magbrush::dem::testing {

// Toner, carrier and a 50 GPa wall, the toner with 50 nm asperities.
inline Material toner_material()
{
  Material m = elastic_material("toner", 3e9, 0.35, 1200);
  m.damping = 0.5;
  m.hamaker = 1e-19;
  m.hamaker_given = true;
  m.adhesion_radius = 50e-9;
  return m;
}

// One toner population (7 µm) and, optionally, a carrier population (50 µm); a wall
// material "plate" of 50 GPa with the given Hamaker constant.
inline Case toner_case(bool with_carrier, double plate_hamaker = 2e-19)
{
  Case c = single_species_case(toner_material());
  c.populations[0].name = "toner";
  c.populations[0].kind = ParticleKind::toner;
  c.populations[0].diameter_mean = 7e-6;
  if (with_carrier)
  {
    Material carrier = elastic_material("carrier", 1e9, 0.3, 4800);
    carrier.damping = 0.5;
    carrier.hamaker = 4e-19;
    carrier.hamaker_given = true;
    c.materials.push_back(carrier);
    Population p;
    p.name = "carrier";
    p.material = "carrier";
    p.diameter_mean = 50e-6;
    c.populations.push_back(p);
  }
  Material plate = elastic_material("plate", 50e9, 0.3, 0.0);
  plate.hamaker = plate_hamaker;
  plate.hamaker_given = true;
  plate.friction = 0.4;
  c.materials.push_back(plate);
  return c;
}

inline void add_plate(Case &c, double z = 0.0)
{
  PlaneWall p;
  p.name = "plate";
  p.point = {0, 0, z};
  p.normal = {0, 0, 1};
  p.material = "plate";
  c.planes.push_back(p);
}

// A test-only force: a uniform field along `dir` ramped from zero, q E(t) with E = slope t,
// and an optional constant force on every particle.
class RampedField : public ForceTerm
{
public:
  RampedField(double slope, const Vector3 &dir, const Vector3 &constant = {})
    : slope_(slope), dir_(dir), constant_(constant)
  {
  }
  const char *name() const override { return "ramped_field"; }
  void add_forces(const ParticleState &s, ForceBuffers &f, double t) override
  {
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      const double qE = s.charge[i] * slope_ * t;
      f.fx[i] += qE * dir_.x + constant_.x;
      f.fy[i] += qE * dir_.y + constant_.y;
      f.fz[i] += qE * dir_.z + constant_.z;
    }
  }

private:
  double slope_;
  Vector3 dir_, constant_;
};

inline double pull_off_force(double A, double R) { return A * R / (6.0 * 0.4e-9 * 0.4e-9); }

struct PullOff
{
  double field = 0.0;       // field at which the contact opened [V/m]
  double predicted = 0.0;   // F0 / q
  bool flew_off = false;    // and then left the adhesion range for good
  double dt = 0.0;
};

// A toner (charge q) resting on the plate (or on a fixed carrier below it) in a field ramped
// from zero along +z; returns the field at which it loses contact.
inline PullOff pull_off(bool on_carrier, double ramp_time, double stiffness_factor = 1.0)
{
  omp_set_num_threads(1);
  Case c = toner_case(on_carrier);
  c.dem.toner_stiffness_factor = stiffness_factor;
  if (!on_carrier)
    add_plate(c);
  DemSystem sys(c);
  const double r = 3.5e-6, R = 25e-6, q = 1e-14;
  const Material t = toner_material();
  double F0 = 0.0;
  if (on_carrier)
  {
    sys.particles().add({0, 0, 0}, R, 4800, 1, 0.0);
    sys.particles().add({0, 0, R + r - 1e-10}, r, t.density, 0, q); // touching
    // The carrier's asperity radius is its own radius (adhesion_radius 0).
    F0 = pull_off_force(std::sqrt(1e-19 * 4e-19), 50e-9 * R / (50e-9 + R));
  }
  else
  {
    sys.particles().add({0, 0, r - 1e-10}, r, t.density, 0, q);
    F0 = pull_off_force(std::sqrt(1e-19 * 2e-19), 50e-9);
  }
  PullOff out;
  out.predicted = F0 / q;
  const double slope = 2.0 * out.predicted / ramp_time; // reaches 2 F0 at the end
  sys.add_force_term(std::make_unique<RampedField>(slope, Vector3{0, 0, 1}));
  sys.initialize();
  out.dt = sys.time_step();
  auto &p = sys.particles();
  const auto toner = [&] { return p.id[0] == (on_carrier ? 1 : 0) ? std::size_t{0} : std::size_t{1}; };
  if (on_carrier)
  {
    const std::size_t k = 1 - toner();
    p.inv_mass[k] = 0.0; // the carrier is held in place
  }
  const auto gap = [&] {
    const std::size_t i = toner();
    return on_carrier ? std::sqrt(p.x[i] * p.x[i] + p.y[i] * p.y[i] + p.z[i] * p.z[i]) - R - r : p.z[i] - r;
  };
  while (sys.time() < ramp_time && gap() <= 0.0)
    sys.step();
  out.field = slope * sys.time();
  while (sys.time() < ramp_time && gap() < 1e-6)
    sys.step();
  out.flew_off = gap() >= 1e-6 && p.vz[toner()] > 0.0;
  return out;
}

// A toner thrown at the plate at `speed` from 10 nm above it: the speed it leaves with (0 if
// adhesion captures it within `max_time`), the time it spent in contact, and the steps taken.
struct Rebound
{
  double speed = 0.0, contact_time = 0.0, dt = 0.0;
  long steps = 0;
};

inline Rebound rebound(double speed, double stiffness_factor, double max_time = 20e-6)
{
  omp_set_num_threads(1);
  Case c = toner_case(false);
  c.dem.toner_stiffness_factor = stiffness_factor;
  add_plate(c);
  DemSystem sys(c);
  const double r = 3.5e-6;
  sys.particles().add({0, 0, r + 10e-9}, r, toner_material().density, 0, 0.0);
  sys.initialize();
  auto &p = sys.particles();
  p.vz[0] = -speed;
  Rebound out;
  out.dt = sys.time_step();
  bool touched = false;
  while (sys.time() < max_time)
  {
    sys.step();
    ++out.steps;
    const double gap = p.z[0] - r;
    if (gap < 0.0)
    {
      touched = true;
      out.contact_time += out.dt;
    }
    if (touched && gap > 20e-9 && p.vz[0] > 0.0)
    {
      out.speed = p.vz[0];
      break;
    }
  }
  return out;
}

} // namespace magbrush::dem::testing
