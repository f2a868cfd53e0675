// Physics checks of the integrated engine against exact results:
//  * energy conservation of an undamped, frictionless periodic Hertz gas over 10⁵ steps;
//  * a sphere rolling on a plane, decelerated by rolling friction at a = (5/7) μ_r g;
//  * a particle in a rotating drum brought to the wall's surface speed by friction.
#include "tests/dem/dem_test_scenes.h"
#include "dem/force_terms/gravity.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

TEST(DemPhysics, UndampedPeriodicGasConservesEnergy)
{
  const Material m = elastic_material("gas", 1e7, 0.3, 2500);
  Case c = single_species_case(m);
  const double L = 9e-3, r = 0.5e-3;
  c.dem.periodic_length = c.dem.periodic_length_x = c.dem.periodic_length_y = L;
  c.dem.verlet_skin = 0.3;
  DemSystem sys(c);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto &p = sys.particles();
  // 128 spheres on a lattice with random velocities (no initial overlap).
  const int per_side = 6;
  const double a = L / per_side;
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j)
      for (int k = 0; k < per_side && p.size() < 128; ++k)
      {
        p.add({(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a}, r * (0.8 + 0.4 * u(rng)), m.density, 0, 0.0);
        p.vx.back() = 0.4 * (u(rng) - 0.5);
        p.vy.back() = 0.4 * (u(rng) - 0.5);
        p.vz.back() = 0.4 * (u(rng) - 0.5);
      }
  sys.initialize();
  const double e0 = sys.kinetic_energy() + sys.elastic_energy();
  double worst = 0.0;
  long collisions_seen = 0;
  for (long k = 1; k <= 100000; ++k)
  {
    sys.step();
    if (k % 100 == 0)
    {
      const double e = sys.kinetic_energy() + sys.rotational_energy() + sys.elastic_energy();
      worst = std::max(worst, std::abs(e - e0) / e0);
      collisions_seen += sys.particle_contacts();
    }
  }
  const double e1 = sys.kinetic_energy() + sys.rotational_energy() + sys.elastic_energy();
  std::printf("periodic Hertz gas: 128 spheres, 1e5 steps of %.3g s (%.3g s simulated), %ld list rebuilds, "
              "%ld contacts sampled; |dE|/E: worst %.3g, final %.3g\n",
              sys.time_step(), sys.time(), sys.neighbour_rebuilds(), collisions_seen, worst, std::abs(e1 - e0) / e0);
  EXPECT_GT(collisions_seen, 100);        // it really is a colliding gas
  EXPECT_GT(sys.neighbour_rebuilds(), 10); // and the list really was rebuilt
  // The README quotes the worst drift (measured 2.47e-5, final 1.08e-5).
  EXPECT_LT(std::abs(e1 - e0) / e0, 3e-5);
  EXPECT_LT(worst, 3e-5);
}

TEST(DemPhysics, RollingFrictionDeceleratesRollingSphere)
{
  Material m = elastic_material("ball", 1e8, 0.3, 2500);
  m.friction = 0.5;
  m.rolling_friction = 0.05;
  m.damping = 0.5;
  Case c = single_species_case(m);
  c.dem.gravity = {0.0, 0.0, -9.81};
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1}, 0.3, 0.5);
  DemSystem sys(c);
  const double R = 1e-3, v0 = 0.1, g = 9.81;
  const double mass = m.density * 4.0 / 3.0 * M_PI * R * R * R;
  const double E_star = m.youngs_modulus / (1 - 0.09);
  const double k_n = 4.0 / 3.0 * E_star * std::sqrt(R);
  const double delta0 = std::pow(mass * g / k_n, 2.0 / 3.0); // static Hertz overlap
  sys.particles().add({0, 0, R - delta0}, R, m.density, 0, 0.0);
  sys.particles().vx = {v0};
  sys.particles().wy = {v0 / (R - delta0)}; // rolling without slip
  sys.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys.initialize();
  // Velocity samples after a short settling of the contact springs.
  const double t1 = 0.02, t2 = 0.12;
  double v1 = 0, v2 = 0;
  while (sys.time() < t2)
  {
    sys.step();
    if (v1 == 0 && sys.time() >= t1)
      v1 = sys.particles().vx[0];
  }
  v2 = sys.particles().vx[0];
  const double a = (v1 - v2) / (t2 - t1);
  // Pure rolling: m a = −F, I a / R = F R − μ_r R m g  ⇒  a = μ_r g / (1 + I/(m R²)) = (5/7) μ_r g.
  const double expected = 5.0 / 7.0 * m.rolling_friction * g;
  std::printf("rolling friction: deceleration %.5f m/s^2, expected (5/7) mu_r g = %.5f m/s^2 (%.3f %%)\n", a,
              expected, 100 * (a / expected - 1));
  EXPECT_NEAR(a / expected, 1.0, 1e-2);
  // Still rolling without slip: contact-point speed ≪ centre speed.
  const auto &p = sys.particles();
  EXPECT_LT(std::abs(p.vx[0] - p.wy[0] * (R - delta0)), 1e-3 * v0);
}

TEST(DemPhysics, ParticleInRotatingDrumReachesSurfaceSpeed)
{
  Material m = elastic_material("ball", 1e8, 0.3, 2500);
  m.damping = 0.5;
  Case c = single_species_case(m);
  c.dem.gravity = {0.0, -9.81, 0.0};
  Material wall = elastic_material("drum", 1e10, 0.3, 0.0);
  wall.friction = 0.4;
  c.materials.push_back(wall);
  // A drum of radius 10 mm turning at 30 rpm (surface speed 31.4 mm/s), particle inside.
  CylinderWall drum;
  drum.name = "drum";
  drum.radius = 10e-3;
  drum.omega = 30.0 * 2.0 * M_PI / 60.0;
  drum.particles_outside = false;
  drum.material = "drum";
  WallSet walls;
  walls.cylinders.push_back(drum);
  DemSystem sys(c, walls);
  const double R = 1e-3;
  sys.particles().add({0, -(drum.radius - R), 0}, R, m.density, 0, 0.0);
  sys.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys.initialize();
  const double surface_speed = drum.omega * drum.radius;
  auto slip = [&]() {
    // Velocity of the particle's contact point minus that of the drum surface there.
    const auto &p = sys.particles();
    const Vector3 x = p.position(0), v = p.velocity(0), w = p.angular_velocity(0);
    const double d = std::hypot(x.x, x.y);
    const Vector3 n{x.x / d, x.y / d, 0.0}; // towards the wall
    const double lever = drum.radius - d;   // centre to the wall surface
    const Vector3 vc = v + cross(w, lever * n);
    const Vector3 xw = x + lever * n;
    const Vector3 vw{-drum.omega * xw.y, drum.omega * xw.x, 0.0};
    return norm(vc - vw);
  };
  while (sys.time() < 1e-3)
    sys.step();
  const double early = slip();
  while (sys.time() < 0.5)
    sys.step();
  const double late = slip();
  const auto &p = sys.particles();
  std::printf("rotating drum: slip %.4g m/s at 1 ms, %.3g m/s at 0.5 s (surface speed %.4g m/s); particle spin "
              "%.4g rad/s, spin if its centre were at rest %.4g rad/s\n",
              early, late, surface_speed, p.wz[0], surface_speed / R);
  EXPECT_GT(early, 0.5 * surface_speed); // it starts at rest on a moving wall
  EXPECT_LT(late, 1e-3 * surface_speed);  // friction has brought it to the surface speed
  // (The particle then rolls to and fro about the bottom like a pendulum — rolling without
  // slip dissipates nothing — so its spin is not constant; the contact point moves with the wall.)
}
