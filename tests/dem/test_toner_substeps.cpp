// The toner in substeps of the carriers' step (dem.toner_substeps, dem/toner_substeps.h):
// the number of substeps follows the carriers' own stable step and a larger one is refused;
// the answer is the same bits on one and two threads and across a restart; a toner's impact on
// a carrier and on a wall gives the rebound speed and contact time of the single-step engine;
// the momentum that toner and carriers exchange is conserved; and k = 1 is the engine
// without substeps.
#include "dem/dem_system.h"
#include "dem/force_terms/gravity.h"

#include "case/case_parser.h"

#include "tests/dem/dem_test_scenes.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

// Developer in a periodic box over a floor: 150 carriers (35 um) with their toner (7 um, 5 %,
// adhesive) on their surfaces, falling onto the floor with random velocities. `substeps`:
// dem.toner_substeps; `gravity`: along -z [m/s^2].
Case developer_box(int substeps, double gravity = 9.81)
{
  const std::string yaml = R"(
name: developer
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, friction: 0.45, damping: 0.6, hamaker: 1e-19 J, adhesion_radius: 100 nm}
  toner: {youngs_modulus: 3e3 MPa, poisson_ratio: 0.35, density: 1100 kg/m^3, friction: 0.3, rolling_friction: 0.1, damping: 0.6, hamaker: 1e-19 J, adhesion_radius: 50 nm}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6, hamaker: 1e-19 J}
planes:
  - {name: floor, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
populations:
  - {name: carrier, kind: carrier, diameter: 35 um, diameter_std: 3.5 um, count: 150, insert_box: [[0 mm, 0 mm, 0 mm], [0.5 mm, 0.5 mm, 0.2 mm]]}
  - {name: toner, kind: toner, diameter: 7 um, diameter_std: 1 um, concentration: 5 %, charge_to_mass: -30 uC/g, attached: true}
dem: {periodic_length_x: 0.5 mm, periodic_length_y: 0.5 mm, seed: 7}
)";
  Case c = parse_case_text(yaml, "developer.yaml");
  c.dem.toner_substeps = substeps;
  c.dem.gravity = {0, 0, -gravity};
  c.dem.toner_stiffness_factor = 0.3;
  c.dem.time_step_safety = 0.5;
  return c;
}

std::unique_ptr<DemSystem> make_system(const Case &c, double speed = 0.5)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys->insert_particles();
  give_random_velocities(sys->particles(), 3);
  for (std::size_t i = 0; i < sys->particles().size(); ++i)
  {
    sys->particles().vx[i] *= speed;
    sys->particles().vy[i] *= speed;
    sys->particles().vz[i] *= speed;
  }
  sys->initialize();
  return sys;
}

// Two spheres along x, the first moving towards the second at `v`: a toner on a carrier at
// rest (`on_wall` false), or a toner onto the floor (true). Returns the rebound speed ratio and
// the contact's duration, read from a run of `steps` steps.
struct Impact
{
  double restitution = 0.0, duration = 0.0;
};

Impact toner_impact(int substeps, bool on_wall)
{
  Case c = developer_box(substeps, 0.0);
  c.populations[0].insert_box.reset();
  c.populations[0].count = 1;
  c.populations[1].concentration = 0.0;
  c.populations[1].count = 1;
  c.populations[1].attached = false;
  for (Material &m : c.materials) // no adhesion: the rebound is the contact law's alone
    m.hamaker = 0.0;
  DemSystem sys(c);
  sys.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  ParticleState &p = sys.particles();
  const double rc = 17.5e-6, rt = 3.5e-6, v = 0.5;
  auto add = [&](int species, double r, double rho, double x, double y, double z, double vz) {
    const std::size_t k = p.size();
    p.resize(k + 1);
    p.id[k] = static_cast<std::int32_t>(k);
    p.species[k] = species;
    p.radius[k] = r;
    p.mass[k] = rho * 4.0 / 3.0 * M_PI * r * r * r;
    p.inv_mass[k] = 1.0 / p.mass[k];
    p.inv_inertia[k] = 1.0 / (0.4 * p.mass[k] * r * r);
    p.x[k] = x;
    p.y[k] = y;
    p.z[k] = z;
    p.vz[k] = vz;
  };
  if (on_wall)
    add(0, rc, 2200, 0.1e-3, 0.1e-3, 0.4e-3, 0.0); // a carrier far away (sets the step)
  else
    add(0, rc, 2200, 0.25e-3, 0.25e-3, 0.2e-3, 0.0);
  const double z0 = on_wall ? rt + 0.2e-6 : 0.2e-3 - rc - rt - 0.2e-6;
  add(1, rt, 1100, on_wall ? 0.3e-3 : 0.25e-3, 0.25e-3, z0, on_wall ? -v : v);
  sys.initialize();
  const std::size_t toner = p.species[0] == 1 ? 0 : 1;
  (void)toner;
  double first = -1.0, last = -1.0;
  for (int step = 0; step < 20000; ++step)
  {
    sys.step();
    std::size_t t = 0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.species[k] == 1)
        t = k;
    const bool touching = on_wall ? sys.wall_slots().loads(1)[0].contacts > 0 : sys.particle_contacts() > 0;
    if (touching && first < 0)
      first = sys.time();
    if (!touching && first >= 0 && last < 0)
    {
      last = sys.time();
      Impact out;
      out.duration = last - first;
      // Relative approach speed after / before (the carrier recoils a little).
      double vc = 0.0;
      for (std::size_t k = 0; k < p.size(); ++k)
        if (p.species[k] == 0)
          vc = p.vz[k];
      out.restitution = on_wall ? p.vz[t] / v : (vc - p.vz[t]) / v;
      return out;
    }
  }
  ADD_FAILURE() << "the toner never left the contact";
  return {};
}

} // namespace

TEST(TonerSubsteps, FollowTheCarriersStableStepAndRefuseALargerOne)
{
  omp_set_num_threads(1);
  auto single = make_system(developer_box(1));
  auto automatic = make_system(developer_box(0));
  const TonerSubsteps &s = automatic->toner_substeps();
  std::printf("single step %.4g s; with substeps: step %.4g s = %d x %.4g s (the carriers' limit %.4g s: %s)\n",
              single->time_step(), automatic->time_step(), s.substeps, s.substep, s.carrier_limit,
              s.carrier_limiting.c_str());
  EXPECT_FALSE(single->toner_substeps().on());
  ASSERT_TRUE(s.on());
  EXPECT_GE(s.substeps, 4); // 35 um carriers against 7 um toner: ~5-7
  EXPECT_EQ(s.substep, single->time_step());
  EXPECT_EQ(automatic->time_step(), s.substeps * s.substep);
  EXPECT_LE(automatic->time_step(), s.carrier_limit);
  EXPECT_GT((s.substeps + 1) * s.substep, s.carrier_limit);
  try
  {
    make_system(developer_box(s.substeps + 1));
    ADD_FAILURE() << "one substep more than the carriers allow was accepted";
  }
  catch (const std::invalid_argument &e)
  {
    EXPECT_NE(std::string(e.what()).find("use at most " + std::to_string(s.substeps)), std::string::npos) << e.what();
  }
}

TEST(TonerSubsteps, OneSubstepIsTheEngineWithout)
{
  omp_set_num_threads(1);
  auto a = make_system(developer_box(1));
  for (int k = 0; k < 300; ++k)
    a->step();
  EXPECT_FALSE(a->toner_substeps().on());
  EXPECT_EQ(a->forces().fast_fx, std::vector<double>(a->particles().size(), 0.0));
}

TEST(TonerSubsteps, OneAndTwoThreadsGiveIdenticalBits)
{
  std::vector<double> result[2];
  long contacts = 0, rebuilds = 0;
  std::size_t n = 0;
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    auto sys = make_system(developer_box(0));
    contacts = 0;
    for (int k = 0; k < 400; ++k)
    {
      sys->step();
      contacts += sys->particle_contacts();
    }
    result[threads - 1] = state_by_id(*sys);
    rebuilds = sys->neighbour_rebuilds();
    n = sys->particles().size();
  }
  omp_set_num_threads(2);
  std::printf("1 vs 2 threads with substeps: %zu particles, 400 steps, %ld touching pairs summed over the steps, %ld "
              "list rebuilds\n",
              n, contacts, rebuilds);
  EXPECT_GT(n, 512u); // the parallel path
  EXPECT_GT(contacts, 2000);
  EXPECT_GT(rebuilds, 1);
  EXPECT_TRUE(bit_identical(result[0], result[1]));
}

TEST(TonerSubsteps, RestartContinuesBitIdentically)
{
  omp_set_num_threads(1);
  const Case c = developer_box(0);
  const std::string path = (magbrush::testing::test_temp_dir("toner_substeps") / "restart.bin").string();
  auto a = make_system(c);
  for (int k = 0; k < 200; ++k)
    a->step();
  a->write_checkpoint(path);
  long contacts = 0;
  for (int k = 0; k < 200; ++k)
  {
    a->step();
    contacts += a->particle_contacts();
  }
  DemSystem b(c);
  b.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  b.read_checkpoint(path);
  for (int k = 0; k < 200; ++k)
    b.step();
  EXPECT_EQ(a->time(), b.time());
  EXPECT_GT(contacts, 1000);
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
  std::filesystem::remove(path);
}

// Without gravity and away from the floor, the toner and the carriers only exchange
// momentum. The carriers take each step's reaction as the average over its substeps, half in
// each half kick, so the total drifts by at most the last step's share; it must not grow.
TEST(TonerSubsteps, MomentumIsConserved)
{
  omp_set_num_threads(1);
  Case c = developer_box(0, 0.0);
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0.1e-3}, Vec3{0.5e-3, 0.5e-3, 0.3e-3}};
  auto sys = make_system(c, 0.2);
  auto momentum = [&](double &scale) {
    const ParticleState &p = sys->particles();
    double P[3] = {0, 0, 0};
    scale = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
    {
      P[0] += p.mass[i] * p.vx[i];
      P[1] += p.mass[i] * p.vy[i];
      P[2] += p.mass[i] * p.vz[i];
      scale += p.mass[i] * std::sqrt(p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i] + p.vz[i] * p.vz[i]);
    }
    return std::array<double, 3>{P[0], P[1], P[2]};
  };
  double scale0 = 0.0, scale = 0.0;
  const auto P0 = momentum(scale0);
  double worst = 0.0;
  long contacts = 0;
  for (int k = 0; k < 600; ++k)
  {
    sys->step();
    contacts += sys->particle_contacts();
    const auto P = momentum(scale);
    worst = std::max(worst, std::hypot(P[0] - P0[0], P[1] - P0[1], P[2] - P0[2]) / scale0);
  }
  // The toner's impulses within the last step (at most its contact forces times dt) over the
  // total |momentum|: the bound the scheme allows.
  std::printf("momentum drift: worst %.3g of sum m|v| over 600 steps (%ld touching pairs summed over the steps)\n",
              worst, contacts);
  EXPECT_GT(contacts, 2000);
  EXPECT_LT(worst, 1e-3);
}

// A toner's rebound off a carrier and off the floor: restitution and contact time as with one
// step for all (the same contact law, resolved by the substeps).
TEST(TonerSubsteps, ImpactsReboundAsWithoutSubsteps)
{
  omp_set_num_threads(1);
  for (bool wall : {false, true})
  {
    const Impact one = toner_impact(1, wall), sub = toner_impact(0, wall);
    std::printf("toner on %s: restitution %.5f / %.5f, contact %.4g / %.4g s (single step / substeps)\n",
                wall ? "the floor" : "a carrier", one.restitution, sub.restitution, one.duration, sub.duration);
    EXPECT_GT(one.restitution, 0.3);
    EXPECT_NEAR(sub.restitution, one.restitution, 0.01 * one.restitution);
    // Contact detected at step ends: the substeps' step is k times longer.
    EXPECT_NEAR(sub.duration, one.duration, 1.5 * make_system(developer_box(0))->time_step());
  }
}
