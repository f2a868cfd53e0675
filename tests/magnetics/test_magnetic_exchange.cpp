// Carriers leaving and entering a running scene with the induced-dipole magnetics on: the
// term drops the leavers from its compact order, keeps the survivors' dipoles as the initial
// guess, appends the newcomers (ForceTerm::particles_changed) and solves the new set in full;
// its forces equal those of a fresh term solving the same state from scratch, to within the
// solver tolerance, and the warm start needs fewer sweeps than the fresh solve.
#include "dem/force_terms/magnetic_force_term.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"
#include "dem/dem_system.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unistd.h>

using namespace magbrush;
using namespace magbrush::magnetics;

namespace {
const char *scene = R"(
name: magnetic_exchange
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, mu_r: 3.9, friction: 0.45, damping: 0.6}
  toner: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 1000 kg/m^3, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 60 um, diameter_std: 6 um, count: 500, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]]}
  - {name: toner, kind: toner, material: toner, diameter: 8 um, count: 100, charge_to_mass: -30 uC/g, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]]}
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
applied_field: {kind: uniform, direction: [0, 0, 1], magnitude: 130 mT}
dem: {time_step: 5 ns, periodic_length_x: 1 mm, periodic_length_y: 1 mm, magnetic_refresh: 5 us, magnetic_tolerance: 1e-7, magnetic_far_field: none, magnetic_cutoff: 4, gravity: [0, 0, -9.81 m/s^2], seed: 3}
)";

// The largest difference between the term's last forces and a fresh solve of the same state,
// relative to the largest magnetic force (`only`: of these engine indices; empty = all).
double difference_to_fresh_solve(const Case &c, const dem::DemSystem &system, const MagneticForceTerm &term,
                                 int &fresh_sweeps, const std::vector<std::size_t> &only = {})
{
  std::vector<double> fx, fy, fz;
  term.last_forces(fx, fy, fz);
  MagneticForceTerm fresh(c, MagneticSettings::from_case(c.dem), AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                          system.box().length);
  dem::ForceBuffers f;
  f.resize(system.particles().size());
  fresh.add_forces(system.particles(), f, system.time());
  fresh_sweeps = fresh.last_stats().sweeps;
  double worst = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < fx.size(); ++i)
    largest = std::max(largest, std::hypot(f.fx[i], f.fy[i], f.fz[i]));
  auto differ = [&](std::size_t i) {
    worst = std::max(worst, std::hypot(fx[i] - f.fx[i], fy[i] - f.fy[i], fz[i] - f.fz[i]));
  };
  if (only.empty())
    for (std::size_t i = 0; i < fx.size(); ++i)
      differ(i);
  for (std::size_t i : only)
    differ(i);
  EXPECT_GT(largest, 0.0);
  return worst / largest;
}
} // namespace

TEST(MagneticForceTerm, CarriersLeavingAndEnteringKeepTheSolverConsistent)
{
  omp_set_num_threads(2);
  const Case c = parse_case_text(scene, "magnetic_exchange.yaml");
  dem::DemSystem system(c);
  MagneticSettings settings = MagneticSettings::from_case(c.dem);
  settings.defer_exchange = false; // the full evaluation at the exchange (see the test below)
  auto owned = std::make_unique<MagneticForceTerm>(c, settings, AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                                                   system.box().length);
  const MagneticForceTerm *term = owned.get();
  system.add_force_term(std::move(owned));
  system.insert_particles();
  system.initialize();
  system.advance(40);
  const long evaluations = term->evaluations();

  // Every 7th particle leaves (carriers and toner); 30 carriers and 10 toner enter above the bed.
  std::vector<std::int32_t> leave;
  for (std::size_t i = 0; i < system.particles().size(); ++i)
    if (system.particles().id[i] % 7 == 3)
      leave.push_back(static_cast<std::int32_t>(i));
  dem::ParticleState enter;
  for (int k = 0; k < 40; ++k)
  {
    const bool carrier = k < 30;
    enter.add({0.1e-3 * (k % 10) + 0.05e-3, 0.25e-3 * (k / 10) + 0.1e-3, 0.45e-3}, carrier ? 30e-6 : 4e-6,
              carrier ? 2200.0 : 1000.0, carrier ? 0 : 1, 0.0);
  }
  long carriers_before = 0;
  for (int s : system.particles().species)
    carriers_before += s == 0;
  system.exchange_particles(leave, enter);
  system.step();
  long carriers_after = 0;
  for (int s : system.particles().species)
    carriers_after += s == 0;
  EXPECT_EQ(term->evaluations(), evaluations + 1) << "the changed set is solved once, in full";
  EXPECT_EQ(term->dipoles().dipoles().size(), 3 * static_cast<std::size_t>(carriers_after));
  int fresh_sweeps = 0;
  const double after_exchange = difference_to_fresh_solve(c, system, *term, fresh_sweeps);
  const int warm_sweeps = term->last_stats().sweeps;
  std::printf("exchange with magnetics: carriers %ld -> %ld (%zu particles left, 40 entered); max |F - F_fresh| / max "
              "|F| = %.2e (tolerance %.0e); sweeps warm %d, fresh %d\n",
              carriers_before, carriers_after, leave.size(), after_exchange, c.dem.magnetic_tolerance, warm_sweeps,
              fresh_sweeps);
  EXPECT_LT(after_exchange, 1e-5);
  EXPECT_LT(warm_sweeps, fresh_sweeps) << "the survivors' dipoles should be a better start than none";

  // A second change, removals only, after a few more steps (and a re-sort on the way).
  system.request_neighbour_rebuild();
  system.advance(10);
  leave.clear();
  for (std::size_t i = 0; i < system.particles().size(); i += 11)
    leave.push_back(static_cast<std::int32_t>(i));
  system.exchange_particles(leave, dem::ParticleState{});
  system.step();
  const double after_removal = difference_to_fresh_solve(c, system, *term, fresh_sweeps);
  std::printf("removals only: max |F - F_fresh| / max |F| = %.2e; sweeps warm %d, fresh %d\n", after_removal,
              term->last_stats().sweeps, fresh_sweeps);
  EXPECT_LT(after_removal, 1e-5);
}

// The compact order follows the engine's when the solver learns a new set: after exchanges
// and the engine's re-sorts, the beads are in ascending engine index (cell order), so the
// per-step loops stream over the engine's arrays; the forces still equal a fresh solve. With
// the switch off, the order is the one the exchanges leave (survivors in their old order, the
// newcomers at the end): the same forces, in another order.
TEST(MagneticForceTerm, CompactOrderFollowsTheEnginesAfterExchanges)
{
  omp_set_num_threads(2);
  const Case c = parse_case_text(scene, "magnetic_exchange.yaml");
  for (const bool follow : {true, false})
  {
    dem::DemSystem system(c);
    MagneticSettings settings = MagneticSettings::from_case(c.dem);
    settings.defer_exchange = false; // the exchange is solved at once
    auto owned = std::make_unique<MagneticForceTerm>(c, settings, AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                                                     system.box().length);
    owned->set_follow_engine_order(follow);
    const MagneticForceTerm *term = owned.get();
    system.add_force_term(std::move(owned));
    system.insert_particles();
    system.initialize();
    system.advance(20);
    for (int round = 0; round < 3; ++round)
    {
      system.request_neighbour_rebuild(); // a re-sort: the engine indices move under the term
      system.advance(5);
      std::vector<std::int32_t> leave;
      for (std::size_t i = 0; i < system.particles().size(); ++i)
        if (system.particles().id[i] % 9 == round)
          leave.push_back(static_cast<std::int32_t>(i));
      dem::ParticleState enter;
      for (int k = 0; k < 12; ++k)
        enter.add({0.08e-3 * k + 0.05e-3, 0.2e-3 * round + 0.1e-3, 0.4e-3}, 30e-6, 2200.0, 0, 0.0);
      system.exchange_particles(leave, enter);
      system.request_neighbour_rebuild(); // the newcomers sorted in among the others
      system.step();
    }
    const std::vector<std::uint32_t> &order = term->compact_carriers();
    ASSERT_FALSE(order.empty());
    EXPECT_EQ(std::is_sorted(order.begin(), order.end()), follow)
      << (follow ? "the compact order should follow the engine's" : "the order the exchanges leave is not sorted");
    int fresh_sweeps = 0;
    const double difference = difference_to_fresh_solve(c, system, *term, fresh_sweeps);
    std::printf("order %s the engine's after 3 exchanges: max |F - F_fresh| / max |F| = %.2e\n",
                follow ? "following" : "not following", difference);
    EXPECT_LT(difference, 1e-5);
  }
}

// MagneticSettings::defer_exchange (the default): an exchange forces no evaluation. An empty
// one changes nothing; after a real one the newcomers feel the applied field and their
// neighbours' held dipoles (bounded error) until the next full evaluation, which admits them
// and equals a fresh solve again.
TEST(MagneticForceTerm, DeferredExchangeJoinsTheNextFullEvaluation)
{
  omp_set_num_threads(2);
  const Case c = parse_case_text(scene, "magnetic_exchange.yaml");
  dem::DemSystem system(c);
  const MagneticSettings settings = MagneticSettings::from_case(c.dem);
  ASSERT_TRUE(settings.defer_exchange);
  auto owned = std::make_unique<MagneticForceTerm>(c, settings, AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                                                   system.box().length);
  const MagneticForceTerm *term = owned.get();
  system.add_force_term(std::move(owned));
  system.insert_particles();
  system.initialize();
  system.advance(40);
  const long evaluations = term->evaluations();
  const std::size_t dipoles_before = term->dipoles().dipoles().size();

  system.exchange_particles({}, dem::ParticleState{}); // nothing in, nothing out
  system.step();
  EXPECT_EQ(term->evaluations(), evaluations) << "an empty exchange changes nothing";

  std::vector<std::int32_t> leave;
  for (std::size_t i = 0; i < system.particles().size(); ++i)
    if (system.particles().id[i] % 7 == 3)
      leave.push_back(static_cast<std::int32_t>(i));
  dem::ParticleState enter;
  for (int k = 0; k < 10; ++k) // ten carriers on the bed's top (0.3 mm)
    enter.add({0.1e-3 * k + 0.05e-3, 0.5e-3, 0.33e-3}, 30e-6, 2200.0, 0, 0.0);
  system.exchange_particles(leave, enter);
  system.step();
  EXPECT_EQ(term->evaluations(), evaluations) << "the exchange waits for the next full evaluation";
  EXPECT_EQ(term->dipoles().dipoles().size(), dipoles_before) << "nobody admitted yet";
  std::vector<std::size_t> newcomers;
  for (std::size_t i = 0; i < system.particles().size(); ++i)
    if (system.particles().id[i] >= 600)
      newcomers.push_back(i);
  ASSERT_EQ(newcomers.size(), 10u);
  int fresh_sweeps = 0;
  const double waiting = difference_to_fresh_solve(c, system, *term, fresh_sweeps, newcomers);
  std::printf("deferred exchange: newcomers' forces before admission: max |F - F_fresh| / max |F| = %.2e\n", waiting);
  EXPECT_LT(waiting, 0.5) << "the newcomers feel the field and their neighbours meanwhile";

  int steps = 0;
  while (term->evaluations() == evaluations && steps < 1100) // the refresh interval: 1000 steps
  {
    system.step();
    ++steps;
  }
  long carriers_after = 0;
  for (int s : system.particles().species)
    carriers_after += s == 0;
  EXPECT_EQ(term->dipoles().dipoles().size(), 3 * static_cast<std::size_t>(carriers_after));
  const double admitted = difference_to_fresh_solve(c, system, *term, fresh_sweeps);
  std::printf("admitted after %d steps: max |F - F_fresh| / max |F| = %.2e\n", steps, admitted);
  EXPECT_LT(admitted, 1e-5);
}

namespace {
// Positions, velocities and forces of every particle in id order (ids are not dense after an
// exchange), as raw doubles.
std::vector<double> state_in_id_order(const dem::DemSystem &s)
{
  const auto &p = s.particles();
  const auto &f = s.forces();
  std::vector<std::size_t> order(p.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(), [&p](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  std::vector<double> out;
  for (std::size_t i : order)
    for (double v : {p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i], f.fx[i], f.fy[i], f.fz[i]})
      out.push_back(v);
  return out;
}
} // namespace

// A checkpoint written while an exchange waits (leavers frozen, newcomers not admitted)
// continues bit for bit: the waiting set is part of the magnetic state.
TEST(MagneticForceTerm, DeferredExchangeSurvivesARestartBitIdentically)
{
  omp_set_num_threads(2);
  const Case c = parse_case_text(scene, "magnetic_exchange.yaml");
  auto make = [&c]() {
    auto system = std::make_unique<dem::DemSystem>(c);
    system->add_force_term(std::make_unique<MagneticForceTerm>(
      c, MagneticSettings::from_case(c.dem), AppliedMagneticField::uniform({0, 0, 1}, 0.13), system->box().length));
    return system;
  };
  auto a = make();
  a->insert_particles();
  a->initialize();
  a->advance(40);
  std::vector<std::int32_t> leave;
  for (std::size_t i = 0; i < a->particles().size(); i += 13)
    leave.push_back(static_cast<std::int32_t>(i));
  dem::ParticleState enter;
  for (int k = 0; k < 6; ++k)
    enter.add({0.15e-3 * k + 0.05e-3, 0.3e-3, 0.33e-3}, 30e-6, 2200.0, 0, 0.0);
  a->exchange_particles(leave, enter);
  a->advance(5);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("magnetic_exchange_restart_" + std::to_string(::getpid()) + ".bin")).string();
  a->write_checkpoint(path);
  auto b = make();
  b->read_checkpoint(path);
  std::filesystem::remove(path);
  for (const auto &t : b->force_terms())
  {
    if (const auto *m = dynamic_cast<const MagneticForceTerm *>(t.get()))
    {
      EXPECT_TRUE(m->restored_state());
    }
  }
  for (auto *s : {a.get(), b.get()})
    s->advance(1200); // past the refresh interval: the waiting exchange is admitted
  EXPECT_EQ(state_in_id_order(*a), state_in_id_order(*b));
}

// Many newcomers at once (more than the term lets wait: each waiting one costs a sum over all
// carriers per step) are admitted at the next step, by a full evaluation.
TEST(MagneticForceTerm, DeferredExchangeAdmitsALargeBatchAtOnce)
{
  omp_set_num_threads(2);
  const Case c = parse_case_text(scene, "magnetic_exchange.yaml");
  dem::DemSystem system(c);
  auto owned = std::make_unique<MagneticForceTerm>(c, MagneticSettings::from_case(c.dem),
                                                   AppliedMagneticField::uniform({0, 0, 1}, 0.13), system.box().length);
  const MagneticForceTerm *term = owned.get();
  system.add_force_term(std::move(owned));
  system.insert_particles();
  system.initialize();
  system.advance(20);
  const long evaluations = term->evaluations();
  dem::ParticleState enter;
  for (int k = 0; k < 70; ++k)
    enter.add({0.1e-3 * (k % 10) + 0.05e-3, 0.14e-3 * (k / 10) + 0.05e-3, 0.45e-3}, 30e-6, 2200.0, 0, 0.0);
  system.exchange_particles({}, enter);
  system.step();
  EXPECT_EQ(term->evaluations(), evaluations + 1);
  EXPECT_EQ(term->dipoles().dipoles().size(), 3u * 570u);
  int fresh_sweeps = 0;
  EXPECT_LT(difference_to_fresh_solve(c, system, *term, fresh_sweeps), 1e-5);
}
