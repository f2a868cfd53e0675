// Engine guarantees: results independent of the thread count (bit for bit), restarts that
// continue bit-identically, contact history that survives neighbour-list rebuilds and
// re-sorting, stability guards that stop with a useful message, refusal of unstable user
// time steps, insertion, and the contact-law building blocks.
#include "tests/dem/dem_test_scenes.h"
#include "dem/force_terms/gravity.h"
#include "dem/force_terms/stokes_drag.h"

#include "dem/insertion.h"
#include "dem/dem_run.h"
#include "dem/snapshot_writer.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

// ~1500 falling spheres (dem_test_scenes.h): every code path within a few hundred steps.
Case packing_case() { return falling_spheres_case(1500, 3e-3, 0.3e-3, 42); }

std::unique_ptr<DemSystem> make_packing(const Case &c)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys->insert_particles();
  give_random_velocities(sys->particles(), 3);
  sys->initialize();
  return sys;
}


} // namespace

TEST(DemEngine, OneAndTwoThreadsGiveIdenticalBits)
{
  const Case c = packing_case();
  std::vector<double> result[2];
  long contacts = 0, rebuilds = 0;
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    auto sys = make_packing(c);
    for (int k = 0; k < 1500; ++k)
      sys->step();
    result[threads - 1] = state_by_id(*sys);
    contacts = sys->particle_contacts();
    rebuilds = sys->neighbour_rebuilds();
  }
  omp_set_num_threads(2);
  std::printf("1 vs 2 threads: 1500 particles, 1500 steps, %ld contacts at the end, %ld list rebuilds\n", contacts,
              rebuilds);
  EXPECT_GT(contacts, 50);
  EXPECT_GT(rebuilds, 2);
  EXPECT_TRUE(bit_identical(result[0], result[1]));
}

TEST(DemEngine, RestartContinuesBitIdentically)
{
  omp_set_num_threads(1); // thread independence is the test above; keep this one quick
  const Case c = packing_case();
  const std::string path = (magbrush::testing::test_temp_dir("dem_restart") / "restart.bin").string();
  auto a = make_packing(c);
  for (int k = 0; k < 600; ++k)
    a->step();
  a->write_checkpoint(path);
  for (int k = 0; k < 600; ++k)
    a->step();

  DemSystem b(c);
  b.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  b.read_checkpoint(path);
  EXPECT_EQ(b.step_count(), 600);
  for (int k = 0; k < 600; ++k)
    b.step();
  EXPECT_EQ(a->step_count(), b.step_count());
  EXPECT_EQ(a->time(), b.time());
  EXPECT_GT(a->particle_contacts(), 50);
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
  std::filesystem::remove(path);
}

TEST(DemEngine, CorruptCheckpointIsRefused)
{
  const std::string path = (magbrush::testing::test_temp_dir("dem_bad_checkpoint") / "bad.bin").string();
  std::ofstream(path) << "not a checkpoint";
  DemSystem s(packing_case());
  try
  {
    s.read_checkpoint(path);
    FAIL() << "a corrupt checkpoint was accepted";
  }
  catch (const std::runtime_error &e)
  {
    EXPECT_NE(std::string(e.what()).find("not a magbrush DEM checkpoint"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(DemEngine, HistorySurvivesRebuildAndResorting)
{
  // Clumps of touching spheres; set an antisymmetric history on every touching pair; move
  // everything by a fraction of the periodic box (the cell order, hence the particle order,
  // changes); rebuild: every pair must find its history again, with the right sign.
  ParticleState s;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double L = 4e-3, r = 50e-6;
  for (int clump = 0; clump < 60; ++clump)
  {
    const Vector3 c{L * u(rng), L * u(rng), L * u(rng)};
    for (int k = 0; k < 4; ++k)
      s.add({c.x + 1.8 * r * k, c.y + 0.3 * r * (k % 2), c.z}, r, 2000, 0, 0.0);
  }
  PeriodicBox box;
  box.length = {L, L, L};
  NeighbourList list;
  std::vector<double> scratch;
  std::vector<std::int32_t> iscratch;
  auto permute = [&](const std::vector<std::int32_t> &order) { s.permute(order, scratch, iscratch); };
  list.rebuild(s, box, 20e-6, permute);
  auto h = [](int a, int b) { return Vector3{double(a - b), double(a * a - b * b), std::pow(double(a - b), 3)}; };
  auto touching = [&](std::size_t i, std::size_t p) {
    const std::size_t j = static_cast<std::size_t>(list.partner[p]);
    const Vector3 sh = list.shift(p);
    const Vector3 d{s.x[j] - s.x[i] + sh.x, s.y[j] - s.y[i] + sh.y, s.z[j] - s.z[i] + sh.z};
    return norm(d) < s.radius[i] + s.radius[j];
  };
  long set = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::int32_t p = list.row_start[i]; p < list.row_start[i + 1]; ++p)
    {
      const std::size_t q = static_cast<std::size_t>(p);
      list.touching[q] = touching(i, q);
      const Vector3 v = list.touching[q] ? h(s.id[i], s.id[static_cast<std::size_t>(list.partner[q])]) : Vector3{};
      list.hist_x[q] = v.x;
      list.hist_y[q] = v.y;
      list.hist_z[q] = v.z;
      set += list.touching[q];
    }
  ASSERT_GT(set, 100);
  const std::vector<std::int32_t> ids_before = s.id;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    s.x[i] += 0.37 * L; // wraps: the sorted order changes
    s.y[i] += 0.61 * L;
  }
  list.rebuild(s, box, 20e-6, permute);
  EXPECT_NE(ids_before, s.id) << "the test must re-sort the particles";
  long found = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::int32_t p = list.row_start[i]; p < list.row_start[i + 1]; ++p)
    {
      const std::size_t q = static_cast<std::size_t>(p);
      if (!touching(i, q))
        continue;
      const Vector3 want = h(s.id[i], s.id[static_cast<std::size_t>(list.partner[q])]);
      EXPECT_EQ(list.hist_x[q], want.x);
      EXPECT_EQ(list.hist_y[q], want.y);
      EXPECT_EQ(list.hist_z[q], want.z);
      ++found;
    }
  EXPECT_EQ(found, set);
}

TEST(DemEngine, NeighbourListHoldsExactlyThePairsInReach)
{
  // On cell grids of unequal sides, periodic and open, the list must hold every pair closer
  // than r_i + r_j + skin exactly once (i < j in the sorted order), whatever the sort does.
  for (bool periodic : {true, false})
  {
    ParticleState s;
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double r = 50e-6, skin = 20e-6;
    const std::array<double, 3> L{2.3e-3, 1.7e-3, 0.9e-3};
    for (int k = 0; k < 1500; ++k)
      s.add({L[0] * u(rng), L[1] * u(rng), L[2] * u(rng)}, r * (0.6 + 0.4 * u(rng)), 2000, 0, 0.0);
    PeriodicBox box;
    if (periodic)
      box.length = L;
    NeighbourList list;
    std::vector<double> scratch;
    std::vector<std::int32_t> iscratch;
    list.rebuild(s, box, skin, [&](const std::vector<std::int32_t> &order) { s.permute(order, scratch, iscratch); });
    std::set<std::pair<std::int32_t, std::int32_t>> listed, want;
    for (std::size_t i = 0; i < s.size(); ++i)
      for (std::int32_t p = list.row_start[i]; p < list.row_start[i + 1]; ++p)
      {
        const std::size_t j = static_cast<std::size_t>(list.partner[static_cast<std::size_t>(p)]);
        EXPECT_GT(j, i);
        EXPECT_TRUE(listed.insert({s.id[i], s.id[j]}).second) << "a pair listed twice";
      }
    for (std::size_t i = 0; i < s.size(); ++i)
      for (std::size_t j = i + 1; j < s.size(); ++j)
      {
        double d[3] = {s.x[j] - s.x[i], s.y[j] - s.y[i], s.z[j] - s.z[i]};
        for (int q = 0; q < 3 && periodic; ++q)
          d[q] -= L[static_cast<std::size_t>(q)] * std::round(d[q] / L[static_cast<std::size_t>(q)]);
        const double reach = s.radius[i] + s.radius[j] + skin;
        if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach)
          want.insert({s.id[i], s.id[j]});
      }
    EXPECT_GT(want.size(), 200u);
    EXPECT_EQ(listed, want) << (periodic ? "periodic" : "open");
  }
}

TEST(DemEngine, ForcesAreContinuousAcrossForcedRebuilds)
{
  omp_set_num_threads(1); // thread independence is the test above; keep this one quick
  // The same run with and without extra rebuilds every 50 steps: the tangential springs
  // carry over, so the trajectories agree to rounding (a lost history would show at O(1)).
  const Case c = packing_case();
  auto a = make_packing(c);
  auto b = make_packing(c);
  for (int k = 1; k <= 400; ++k)
  {
    if (k % 50 == 0)
      b->request_neighbour_rebuild();
    a->step();
    b->step();
  }
  const auto sa = state_by_id(*a), sb = state_by_id(*b);
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < sa.size(); i += state_values_per_particle)
    for (std::size_t k = state_force_offset; k < state_force_offset + 3; ++k) // forces
    {
      worst = std::max(worst, std::abs(sa[i + k] - sb[i + k]));
      scale = std::max(scale, std::abs(sa[i + k]));
    }
  std::printf("forced rebuilds: max force difference %.3g N of max force %.3g N (%ld vs %ld rebuilds)\n", worst,
              scale, a->neighbour_rebuilds(), b->neighbour_rebuilds());
  EXPECT_GT(b->neighbour_rebuilds(), a->neighbour_rebuilds());
  EXPECT_LT(worst, 1e-6 * scale);
}

TEST(DemEngine, OverlapGuardStopsWithMessage)
{
  Material m = elastic_material("soft", 1e6, 0.3, 2000);
  Case c = single_species_case(m);
  DemSystem s(c);
  s.particles().add({0, 0, 0}, 1e-3, 2000, 0, 0.0);
  s.particles().add({1.4e-3, 0, 0}, 1e-3, 2000, 0, 0.0); // 60 % overlap
  try
  {
    s.initialize();
    FAIL() << "no guard";
  }
  catch (const StabilityError &e)
  {
    const std::string w = e.what();
    EXPECT_NE(w.find("step 0"), std::string::npos) << w;
    EXPECT_NE(w.find("particle id"), std::string::npos) << w;
    EXPECT_NE(w.find("overlaps"), std::string::npos) << w;
    EXPECT_NE(w.find("time step"), std::string::npos) << w;
    std::printf("guard message: %s\n", w.c_str());
  }
}

TEST(DemEngine, NaNGuardStopsWithMessage)
{
  Material m = elastic_material("m", 1e7, 0.3, 2000);
  Case c = single_species_case(m);
  DemSystem s(c);
  s.particles().add({0, 0, 0}, 1e-3, 2000, 0, 0.0);
  s.particles().add({5e-3, 0, 0}, 1e-3, 2000, 0, 0.0);
  s.initialize();
  s.step();
  s.particles().vx[1] = std::nan("");
  try
  {
    s.step();
    FAIL() << "no guard";
  }
  catch (const StabilityError &e)
  {
    const std::string w = e.what();
    EXPECT_NE(w.find("NaN"), std::string::npos) << w;
    EXPECT_NE(w.find("step 2"), std::string::npos) << w;
    EXPECT_NE(w.find("particle id"), std::string::npos) << w;
  }
}

namespace {
// A force term that pumps energy in (negative drag): the runaway guard must catch it.
class EnergyPump : public ForceTerm
{
public:
  const char *name() const override { return "energy pump"; }
  void add_forces(const ParticleState &s, ForceBuffers &f, double) override
  {
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      f.fx[i] += 2e4 * s.mass[i] * s.vx[i];
      f.fy[i] += 2e4 * s.mass[i] * s.vy[i];
      f.fz[i] += 2e4 * s.mass[i] * s.vz[i];
    }
  }
};
} // namespace

TEST(DemEngine, KineticEnergyRunawayGuardStopsWithMessage)
{
  Material m = elastic_material("m", 1e7, 0.3, 2000);
  Case c = single_species_case(m);
  c.dem.max_kinetic_energy_growth = 10.0;
  DemSystem s(c);
  s.particles().add({0, 0, 0}, 1e-3, 2000, 0, 0.0);
  s.particles().vx = {1.0};
  s.add_force_term(std::make_unique<EnergyPump>());
  s.initialize();
  try
  {
    for (int k = 0; k < 100000; ++k)
      s.step();
    FAIL() << "no guard";
  }
  catch (const StabilityError &e)
  {
    const std::string w = e.what();
    EXPECT_NE(w.find("kinetic energy grew"), std::string::npos) << w;
    EXPECT_NE(w.find("particle id 0"), std::string::npos) << w;
    EXPECT_NE(w.find("time_step"), std::string::npos) << w;
  }
}

TEST(DemEngine, UserTimeStepAboveStableLimitIsRefused)
{
  Material m = elastic_material("carrier", 1e9, 0.35, 5000);
  Case c = single_species_case(m);
  DemSystem probe(c);
  probe.particles().add({0, 0, 0}, 30e-6, m.density, 0, 0.0);
  probe.initialize();
  const double limit = probe.stable_time_step_info().limit;
  // Rayleigh time of a 60 µm carrier: π r √(ρ/G) / (0.1631 ν + 0.8766).
  const double G = 1e9 / 2.7;
  EXPECT_NEAR(probe.stable_time_step_info().rayleigh,
              M_PI * 30e-6 * std::sqrt(5000 / G) / (0.1631 * 0.35 + 0.8766), 1e-15);
  EXPECT_NEAR(probe.time_step(), 0.2 * limit, 1e-18);

  c.dem.time_step = 1.5 * limit;
  DemSystem s(c);
  s.particles().add({0, 0, 0}, 30e-6, m.density, 0, 0.0);
  try
  {
    s.initialize();
    FAIL() << "an unstable time step was accepted";
  }
  catch (const std::invalid_argument &e)
  {
    const std::string w = e.what();
    char expected[32];
    std::snprintf(expected, sizeof expected, "%.4g s", limit);
    EXPECT_NE(w.find("above the stable limit"), std::string::npos) << w;
    EXPECT_NE(w.find(expected), std::string::npos) << w;
    std::printf("refusal: %s\n", w.c_str());
  }
  c.dem.time_step = 0.9 * limit; // below the limit: accepted as given
  DemSystem ok(c);
  ok.particles().add({0, 0, 0}, 30e-6, m.density, 0, 0.0);
  ok.initialize();
  EXPECT_EQ(ok.time_step(), 0.9 * limit);
}

TEST(DemEngine, InsertionByMassWithoutOverlap)
{
  Case c = packing_case();
  c.populations[0].count = 0;
  const double rho = 2200, target = 1500 * rho * M_PI / 6 * std::pow(100e-6, 3);
  c.populations[0].mass = target;
  DemSystem s(c);
  s.insert_particles();
  const auto &p = s.particles();
  double mass = 0, mean = 0, m_max = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    mass += p.mass[i];
    mean += 2 * p.radius[i];
    m_max = std::max(m_max, p.mass[i]);
    ASSERT_GT(p.radius[i], 0.0);
    ASSERT_GE(p.z[i], p.radius[i]); // not through the stage
  }
  mean /= static_cast<double>(p.size());
  EXPECT_GE(mass, target);
  EXPECT_LT(mass, target + m_max);
  EXPECT_NEAR(mean, 100e-6, 3 * 10e-6 / std::sqrt(double(p.size())));
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
    {
      double d[3] = {p.x[j] - p.x[i], p.y[j] - p.y[i], p.z[j] - p.z[i]};
      for (int k = 0; k < 2; ++k)
        d[k] -= 3e-3 * std::round(d[k] / 3e-3);
      ASSERT_GE(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), p.radius[i] + p.radius[j]);
    }
}

TEST(DemEngine, OverfullInsertionSaysWhatToDo)
{
  Case c = packing_case();
  c.populations[0].count = 20000;
  DemSystem s(c);
  try
  {
    s.insert_particles();
    FAIL() << "an impossible insertion succeeded";
  }
  catch (const std::runtime_error &e)
  {
    EXPECT_NE(std::string(e.what()).find("enlarge the insertion region"), std::string::npos) << e.what();
  }
}

TEST(DemEngine, SnapshotIsReadableAndInIdOrder)
{
  omp_set_num_threads(1); // thread independence is the test above; keep this one quick
  const Case c = packing_case();
  auto sys = make_packing(c);
  for (int k = 0; k < 50; ++k)
    sys->step();
  const auto dir = magbrush::testing::test_temp_dir("dem_snapshot") / "out";
  SnapshotWriter w(dir.string());
  w.write(*sys);
  ASSERT_EQ(w.snapshots().size(), 1u);
  const std::string h5 = (dir / w.snapshots()[0].second).string();
  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  std::vector<double> pos(3 * sys->particles().size());
  const hid_t d = H5Dopen2(f, "position", H5P_DEFAULT);
  ASSERT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pos.data()), 0);
  H5Dclose(d);
  H5Fclose(f);
  const auto &p = sys->particles();
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const std::size_t k = static_cast<std::size_t>(p.id[i]);
    ASSERT_EQ(pos[3 * k], p.x[i]);
    ASSERT_EQ(pos[3 * k + 2], p.z[i]);
  }
  std::ifstream x(dir / "particles.xdmf");
  const std::string text((std::istreambuf_iterator<char>(x)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(text.find(w.snapshots()[0].second + ":/position"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "particles.xdmf.tmp"));
  std::filesystem::remove_all(dir);
}

TEST(DemEngine, InsertedParticlesSettleOnTheStage)
{
  omp_set_num_threads(1);
  Material m = elastic_material("carrier", 1e6, 0.35, 2200); // soft: a large step
  m.friction = 0.45;
  m.damping = 0.6;
  Case c = single_species_case(m);
  c.populations[0].diameter_mean = 100e-6;
  c.populations[0].diameter_std = 10e-6;
  c.populations[0].count = 200;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{1e-3, 1e-3, 0.4e-3}};
  c.dem.periodic_length_x = c.dem.periodic_length_y = 1e-3;
  c.dem.gravity = {0, 0, -9.81};
  c.dem.air_viscosity = 1.81e-5;
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1}, 0.3, 0.35);
  c.materials.back().youngs_modulus = 5e10;
  DemSystem s(c);
  s.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  s.add_force_term(std::make_unique<StokesDrag>(c.dem.air_viscosity));
  s.insert_particles();
  s.initialize();
  double released = 0.0; // potential energy the fall can release (to z = r)
  for (std::size_t i = 0; i < s.particles().size(); ++i)
    released += s.particles().mass[i] * 9.81 * (s.particles().z[i] - s.particles().radius[i]);
  s.settle(0.03);
  EXPECT_EQ(s.step_count(), 0);
  EXPECT_EQ(s.time(), 0.0);
  const double ke = s.kinetic_energy() + s.rotational_energy();
  double z_min = 1.0;
  for (std::size_t i = 0; i < s.particles().size(); ++i)
    z_min = std::min(z_min, s.particles().z[i] / s.particles().radius[i]);
  const auto loads = s.wall_loads();
  double weight = 0.0;
  for (double mass : s.particles().mass)
    weight += mass * 9.81;
  std::printf("settling: kinetic energy %.3g of the %.3g J released, lowest centre at %.3f radii, %ld particle "
              "and %ld wall contacts, stage load %.4f of the weight\n",
              ke, released, z_min, s.particle_contacts(), loads[0].contacts, -loads[0].force[2] / weight);
  EXPECT_LT(ke, 1e-3 * released);
  EXPECT_GT(z_min, 0.9); // nobody fell through the stage
  EXPECT_GT(loads[0].contacts, 50);
  EXPECT_NEAR(-loads[0].force[2] / weight, 1.0, 0.05); // at rest, the stage carries the weight
}

namespace {
// Records the times at which the force terms are called.
class ClockRecorder : public ForceTerm
{
public:
  double t_min = 1e300, t_max = -1e300;
  const char *name() const override { return "clock recorder"; }
  void add_forces(const ParticleState &, ForceBuffers &, double t) override
  {
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
};
} // namespace

// Settling happens before t = 0, so that a field ramp or a wall path prescribed from t = 0
// has not started while the particles come to rest (Kawamoto: fall, rest, then the field).
TEST(DemEngine, SettlingRunsBeforeTimeZero)
{
  Material m = elastic_material("m", 1e7, 0.3, 2000);
  Case c = single_species_case(m);
  DemSystem s(c);
  s.particles().add({0, 0, 0}, 1e-3, 2000, 0, 0.0);
  auto recorder = std::make_unique<ClockRecorder>();
  const ClockRecorder &clock = *recorder;
  s.add_force_term(std::move(recorder));
  s.initialize();
  const double settle = 100.5 * s.time_step();
  s.settle(settle);
  // ceil(100.5) = 101 steps from t = -101 dt; forces are first evaluated after the drift.
  EXPECT_DOUBLE_EQ(clock.t_min, -100.0 * s.time_step());
  EXPECT_DOUBLE_EQ(clock.t_max, 0.0);              // ended at t = 0 ...
  EXPECT_EQ(s.step_count(), 0);                    // ... with the clock reset for the run
  EXPECT_EQ(s.time(), 0.0);
}

namespace {
// Counts its samples and remembers their times; writes one line into its file.
class SampleCounter : public Measurement
{
public:
  explicit SampleCounter(double every) : every_(every) {}
  const char *name() const override { return "sample counter"; }
  double interval() const override { return every_; }
  void sample(const DemSystem &s) override { times.push_back(s.time()); }
  void write(const std::string &dir) const override
  {
    std::ofstream(dir + "/samples.txt") << times.size() << "\n";
    written.push_back(times.size());
  }
  void write_state(StateOut &out) const override { out.put_array(times); }
  void read_state(StateIn &in) override { in.get_array(times); }
  int state_version() const override { return version; }
  std::vector<double> times;
  mutable std::vector<std::size_t> written; // the samples held at each write
  int version = 1;

private:
  double every_;
};

// One bead falling in a box, 1 µs steps: a run whose measurements are all there is to it.
Case one_bead_case()
{
  Case c = single_species_case(elastic_material("m", 1e7, 0.3, 2000));
  c.populations[0].count = 1;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{3e-3, 3e-3, 3e-3}};
  c.dem.time_step = 1e-6;
  return c;
}
} // namespace

// A measurement is sampled at its own interval, and its files are written at every checkpoint
// as well as at the end, so that a run stopped later leaves them to its last checkpoint (and a
// long one can be watched).
TEST(DemEngine, MeasurementsAreSampledAtTheirIntervalAndWrittenAtEveryCheckpoint)
{
  Case c = one_bead_case();
  c.dem.duration = 100e-6;
  c.dem.checkpoint_interval = 30e-6;
  const std::string dir = (magbrush::testing::test_temp_dir("dem_measurement") / "out").string();
  RunOptions o;
  o.output_dir = dir;
  o.threads = 1;
  std::ostringstream log;
  DemRun run(c, o, log);
  auto counter = std::make_unique<SampleCounter>(10e-6);
  const SampleCounter &seen = *counter;
  run.add_measurement(std::move(counter));
  run.run();
  ASSERT_EQ(seen.times.size(), 10u); // t = 10, 20, ..., 100 µs
  for (std::size_t k = 0; k < seen.times.size(); ++k)
    EXPECT_NEAR(seen.times[k], 10e-6 * static_cast<double>(k + 1), 1e-12);
  std::ifstream in(dir + "/samples.txt");
  int n = 0;
  in >> n;
  EXPECT_EQ(n, 10);
  EXPECT_EQ(seen.written, (std::vector<std::size_t>{3, 6, 9, 10})) << log.str(); // 30, 60, 90 µs; the end
  EXPECT_TRUE(std::filesystem::exists(dir + "/summary.csv"));
  std::filesystem::remove_all(dir);
}

// A measurement's state is in every checkpoint: a run restarted from one continues it (the
// samples before the restart and after, as one run), the log says so; a restart that changes
// what is measured (a statistics key) starts it afresh and says why.
TEST(DemEngine, MeasurementsContinueAcrossARestartUnlessHowTheyMeasureChanged)
{
  Case c = one_bead_case();
  c.dem.duration = 50e-6;
  const auto dir = magbrush::testing::test_temp_dir("dem_measurement_restart");
  RunOptions o;
  o.output_dir = (dir / "first").string();
  o.threads = 1;
  auto run_with_counter = [](const Case &cs, const RunOptions &opts, std::ostringstream &log, int version = 1) {
    DemRun run(cs, opts, log);
    auto counter = std::make_unique<SampleCounter>(10e-6);
    counter->version = version;
    const SampleCounter &seen = *counter;
    run.add_measurement(std::move(counter));
    run.run();
    return seen.times;
  };
  std::ostringstream log1;
  ASSERT_EQ(run_with_counter(c, o, log1).size(), 5u); // 10 ... 50 µs

  Case longer = c;
  longer.dem.duration = 100e-6;
  RunOptions r = o;
  r.restart_file = (dir / "first" / "checkpoint.bin").string();
  r.output_dir = (dir / "continued").string();
  std::ostringstream log2;
  const std::vector<double> continued = run_with_counter(longer, r, log2);
  ASSERT_EQ(continued.size(), 10u) << log2.str();
  for (std::size_t k = 0; k < continued.size(); ++k)
    EXPECT_NEAR(continued[k], 10e-6 * static_cast<double>(k + 1), 1e-12);
  EXPECT_NE(log2.str().find("the measurements continue from the checkpoint"), std::string::npos) << log2.str();

  Case judged_otherwise = longer;
  judged_otherwise.statistics.blocks = longer.statistics.blocks + 2;
  r.output_dir = (dir / "afresh").string();
  std::ostringstream log3;
  const std::vector<double> afresh = run_with_counter(judged_otherwise, r, log3);
  ASSERT_EQ(afresh.size(), 5u) << log3.str(); // 60 ... 100 µs
  EXPECT_NEAR(afresh.front(), 60e-6, 1e-12);
  EXPECT_NE(log3.str().find("the measurements start afresh at the restart (statistics.blocks changed)"),
            std::string::npos)
      << log3.str();

  // A measurement whose state has a new layout (state_version 2) does not read the old one.
  r.output_dir = (dir / "new_layout").string();
  std::ostringstream log4;
  ASSERT_EQ(run_with_counter(longer, r, log4, 2).size(), 5u) << log4.str();
  EXPECT_NE(log4.str().find("keeps the sample counter in another layout than this magbrush's ('sample counter (state "
                            "v2)')"),
            std::string::npos)
      << log4.str();
  // ... and continues from a checkpoint in its own.
  RunOptions v2 = r;
  v2.restart_file = (dir / "new_layout" / "checkpoint.bin").string();
  v2.output_dir = (dir / "new_layout_continued").string();
  Case longest = longer;
  longest.dem.duration = 150e-6;
  std::ostringstream log5;
  EXPECT_EQ(run_with_counter(longest, v2, log5, 2).size(), 10u) << log5.str();
  std::filesystem::remove_all(dir);
}

// The vectorised pair kernel (whichever clone the CPU selects: AVX-512, AVX2 or SSE2) against
// the contact law evaluated pair by pair in plain scalar code, summed in the order the engine
// documents (each particle: its row in pair order from zero, plus its column in ascending pair
// order from zero). Two species of different materials and sizes (the per-type coefficient lookup),
// polydisperse, spinning, with tangential histories built up over earlier steps and pairs in
// the list that do not touch: the forces, torques and histories must agree bit for bit, on
// one thread (rows and columns in one pass) and on two (the column pass after a barrier).
namespace {
void pair_kernel_matches_scalar_contact_law(int threads)
{
  omp_set_num_threads(threads);
  Material a = elastic_material("carrier", 1e9, 0.35, 2200);
  a.friction = 0.45;
  a.polygon_angles = 12;
  a.damping = 0.6;
  Material b = elastic_material("toner", 3e9, 0.3, 1200);
  b.friction = 0.3;
  b.rolling_friction = 0.1;
  b.damping = 0.3;
  Case c = single_species_case(a);
  c.materials.push_back(b);
  Population pb = c.populations[0];
  pb.name = "toner";
  pb.material = "toner";
  c.populations.push_back(pb);
  const int side = 10;
  const double spacing = 60e-6, L = side * spacing;
  c.dem.periodic_length = c.dem.periodic_length_x = c.dem.periodic_length_y = L;
  c.dem.verlet_skin = 0.3;
  DemSystem sys(c);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto &p = sys.particles();
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < side; ++k)
      {
        const int species = (i + 2 * j + 3 * k) % 3 == 0 ? 1 : 0;
        const double r = (species ? 27e-6 : 30.2e-6) * (1.0 + 0.01 * u(rng));
        p.add({(i + 0.5) * spacing + 0.6e-6 * u(rng), (j + 0.5) * spacing + 0.6e-6 * u(rng),
               (k + 0.5) * spacing + 0.6e-6 * u(rng)},
              r, species ? 1200 : 2200, species, 0.0);
        p.vx.back() = 0.1 * u(rng);
        p.vy.back() = 0.1 * u(rng);
        p.vz.back() = 0.1 * u(rng);
        p.wx.back() = 2e3 * u(rng);
        p.wy.back() = 2e3 * u(rng);
        p.wz.back() = 2e3 * u(rng);
      }
  sys.initialize();
  for (int k = 0; k < 40; ++k)
    sys.step();

  // The state the next step's contact kernel will see: the list as it is (no rebuild may
  // happen in that step) with its histories, and the kicked and drifted particles, computed
  // here with the engine's own arithmetic.
  const NeighbourList &list = sys.neighbour_list();
  const std::vector<double> hx0 = list.hist_x, hy0 = list.hist_y, hz0 = list.hist_z;
  ParticleState s = p;
  const ForceBuffers &f = sys.forces();
  const double dt = sys.time_step(), h = 0.5 * dt;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    s.vx[i] += h * f.fx[i] * s.inv_mass[i];
    s.vy[i] += h * f.fy[i] * s.inv_mass[i];
    s.vz[i] += h * f.fz[i] * s.inv_mass[i];
    s.wx[i] += h * f.tx[i] * s.inv_inertia[i];
    s.wy[i] += h * f.ty[i] * s.inv_inertia[i];
    s.wz[i] += h * f.tz[i] * s.inv_inertia[i];
    s.x[i] += dt * s.vx[i];
    s.y[i] += dt * s.vy[i];
    s.z[i] += dt * s.vz[i];
  }
  const long rebuilds = sys.neighbour_rebuilds();
  sys.step();
  ASSERT_EQ(sys.neighbour_rebuilds(), rebuilds) << "the reference assumes the step keeps its list";

  const std::size_t n = s.size(), P = list.pairs();
  std::vector<ContactOutcome> out(P);
  std::vector<Vector3> hist(P);
  std::vector<int> touch(P, 0);
  long touching = 0, listed_apart = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::int32_t pp = list.row_start[i]; pp < list.row_start[i + 1]; ++pp)
    {
      const std::size_t q = static_cast<std::size_t>(pp), j = static_cast<std::size_t>(list.partner[q]);
      const Vector3 sh = list.shift(q);
      const Vector3 d{s.x[j] - s.x[i] + sh.x, s.y[j] - s.y[i] + sh.y, s.z[j] - s.z[i] + sh.z};
      const double reach = s.radius[i] + s.radius[j], r2 = dot(d, d);
      if (!(r2 < reach * reach))
      {
        ++listed_apart;
        continue; // outputs and history zero
      }
      ++touching;
      touch[q] = 1;
      const double dist = std::sqrt(r2), inv_dist = 1.0 / dist;
      ContactKinematics k;
      k.n = inv_dist * d;
      k.overlap = reach - dist;
      k.lever_i = 0.5 * (dist + (s.radius[i] * s.radius[i] - s.radius[j] * s.radius[j]) * inv_dist);
      k.lever_j = dist - k.lever_i;
      const Vector3 wi = s.angular_velocity(i), wj = s.angular_velocity(j);
      k.v_rel = (s.velocity(i) - s.velocity(j)) + cross(k.lever_i * wi + k.lever_j * wj, k.n);
      k.w_rel = wi - wj;
      k.R_star = s.radius[i] * s.radius[j] / reach;
      k.m_star = s.mass[i] * s.mass[j] / (s.mass[i] + s.mass[j]);
      k.radius_i = s.radius[i];
      k.radius_j = s.radius[j];
      k.inv_inertia_i = s.inv_inertia[i];
      k.inv_inertia_j = s.inv_inertia[j];
      hist[q] = {hx0[q], hy0[q], hz0[q]};
      out[q] = evaluate_contact(sys.contact_table().particle_pair(s.species[i], s.species[j]), k, hist[q], dt);
    }
  // Sum in the documented order.
  std::vector<double> ref(6 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    double a6[6] = {0, 0, 0, 0, 0, 0};
    for (std::int32_t pp = list.row_start[i]; pp < list.row_start[i + 1]; ++pp)
    {
      const ContactOutcome &o = out[static_cast<std::size_t>(pp)];
      a6[0] += o.force_i.x, a6[1] += o.force_i.y, a6[2] += o.force_i.z;
      a6[3] += o.torque_i.x, a6[4] += o.torque_i.y, a6[5] += o.torque_i.z;
    }
    std::copy(a6, a6 + 6, &ref[6 * i]);
  }
  // Each column sums from zero in ascending pair order, and is then added to its row's sum.
  std::vector<double> column(6 * n, 0.0);
  for (std::size_t q = 0; q < P; ++q)
  {
    const std::size_t j = static_cast<std::size_t>(list.partner[q]);
    column[6 * j + 0] -= out[q].force_i.x, column[6 * j + 1] -= out[q].force_i.y, column[6 * j + 2] -= out[q].force_i.z;
    column[6 * j + 3] += out[q].torque_j.x, column[6 * j + 4] += out[q].torque_j.y, column[6 * j + 5] += out[q].torque_j.z;
  }
  for (std::size_t k = 0; k < 6 * n; ++k)
    ref[k] += column[k];
  std::printf("kernel vs scalar law: %zu particles (2 species), %zu listed pairs, %ld touching, %ld listed but apart\n",
              n, P, touching, listed_apart);
  ASSERT_GT(touching, 1000);
  ASSERT_GT(listed_apart, 100);
  long mismatches = 0;
  const ForceBuffers &g = sys.forces();
  for (std::size_t i = 0; i < n; ++i)
  {
    const double got[6] = {g.fx[i], g.fy[i], g.fz[i], g.tx[i], g.ty[i], g.tz[i]};
    for (int c6 = 0; c6 < 6; ++c6)
      mismatches += std::memcmp(&got[c6], &ref[6 * i + static_cast<std::size_t>(c6)], sizeof(double)) != 0 &&
                    !(got[c6] == 0.0 && ref[6 * i + static_cast<std::size_t>(c6)] == 0.0);
  }
  for (std::size_t q = 0; q < P; ++q)
  {
    const Vector3 want = touch[q] ? hist[q] : Vector3{};
    mismatches += list.hist_x[q] != want.x || list.hist_y[q] != want.y || list.hist_z[q] != want.z ||
                  list.touching[q] != touch[q];
  }
  EXPECT_EQ(mismatches, 0) << "on " << threads << " thread(s)";
}
} // namespace

TEST(DemEngine, VectorisedPairKernelMatchesScalarContactLaw)
{
  pair_kernel_matches_scalar_contact_law(1);
  pair_kernel_matches_scalar_contact_law(2);
  omp_set_num_threads(2);
}

namespace {
// A force term that adds a small position-dependent pull (so that it matters for the bits)
// and, from step `poison_step` on, a NaN or a huge push on particle index 0. It can declare
// itself a team term (called by every thread inside the engine's team) or a serial one.
class ProbeTerm : public ForceTerm
{
public:
  ProbeTerm(bool in_team, double dt, long poison_step, double poison)
    : in_team_(in_team), dt_(dt), poison_step_(poison_step), poison_(poison) {}
  const char *name() const override { return in_team_ ? "probe (team)" : "probe (serial)"; }
  bool runs_in_team() const override { return in_team_; }
  void add_forces(const ParticleState &s, ForceBuffers &f, double t) override
  {
#pragma omp parallel if (s.size() > 512)
    add_forces_in_team(s, f, t);
  }
  void add_forces_in_team(const ParticleState &s, ForceBuffers &f, double t) override
  {
    const long n = static_cast<long>(s.size());
#pragma omp for schedule(static) nowait
    for (long k = 0; k < n; ++k)
    {
      const std::size_t i = static_cast<std::size_t>(k);
      f.fx[i] += 1e-3 * s.mass[i] * std::sin(1e3 * s.y[i]);
      if (i == 0 && poison_step_ >= 0 && t >= (static_cast<double>(poison_step_) - 0.5) * dt_)
        f.fz[i] += poison_;
    }
  }

private:
  bool in_team_;
  double dt_;
  long poison_step_;
  double poison_;
};

// The packing with gravity (a team term), a serial probe, then Stokes drag (a team term, but
// after a serial one, so it must run serially too: forces are summed in the order of terms).
std::unique_ptr<DemSystem> make_packing_with_terms(const Case &c, bool probe_in_team, long poison_step = -1,
                                                   double poison = 0.0)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys->insert_particles();
  auto &p = sys->particles();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    p.vz[i] = u(rng);
  // The time step is known after initialize(); the probe's poison time uses it, so build a
  // throw-away system to read it first.
  const double dt = [&] {
    DemSystem probe(c);
    probe.particles() = p;
    probe.initialize();
    return probe.time_step();
  }();
  sys->add_force_term(std::make_unique<ProbeTerm>(probe_in_team, dt, poison_step, poison));
  sys->add_force_term(std::make_unique<StokesDrag>(1.8e-5));
  sys->initialize();
  return sys;
}

std::string stability_message(DemSystem &s, bool in_one_call, long steps)
{
  try
  {
    if (in_one_call)
      s.advance(steps);
    else
      for (long k = 0; k < steps; ++k)
        s.step();
  }
  catch (const StabilityError &e)
  {
    return e.what();
  }
  return "(no guard)";
}
} // namespace

// advance(n) keeps the threads in one team between serial work; it must give exactly the
// bits of n calls to step(), with list rebuilds, energy checks, team and serial force terms.
TEST(DemEngine, AdvanceGivesTheBitsOfSingleSteps)
{
  omp_set_num_threads(2);
  const Case c = packing_case();
  for (bool probe_in_team : {true, false})
  {
    auto a = make_packing_with_terms(c, probe_in_team);
    auto b = make_packing_with_terms(c, probe_in_team);
    for (int k = 0; k < 1203; ++k)
      a->step();
    b->advance(1000);
    b->advance(203);
    EXPECT_EQ(a->step_count(), b->step_count());
    EXPECT_EQ(a->time(), b->time());
    EXPECT_GT(b->neighbour_rebuilds(), 2);
    EXPECT_GT(b->particle_contacts(), 50);
    EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(*b))) << "probe in team: " << probe_in_team;
    std::printf("advance(1000) + advance(203) vs 1203 x step(), probe %s: %ld rebuilds, %ld contacts\n",
                probe_in_team ? "in the team" : "serial", b->neighbour_rebuilds(), b->particle_contacts());
  }
}

// A fault inside a batch of steps run by the team stops it at the faulty step, with the
// message a step-by-step run gives.
TEST(DemEngine, GuardsStopAdvanceAtTheFaultyStep)
{
  omp_set_num_threads(2);
  const Case c = packing_case();
  struct Fault
  {
    const char *what;
    double poison;
    const char *expect;
  };
  for (const Fault &f : {Fault{"NaN", std::nan(""), "NaN"}, Fault{"push", -1e3, "overlaps"}})
    for (bool probe_in_team : {true, false})
    {
      auto a = make_packing_with_terms(c, probe_in_team, 137, f.poison);
      auto b = make_packing_with_terms(c, probe_in_team, 137, f.poison);
      const std::string ma = stability_message(*a, false, 1000), mb = stability_message(*b, true, 1000);
      EXPECT_NE(ma.find(f.expect), std::string::npos) << ma;
      EXPECT_EQ(ma, mb) << f.what << ", probe in team: " << probe_in_team;
      EXPECT_EQ(a->step_count(), b->step_count());
      EXPECT_LT(b->step_count(), 200);
      std::printf("%s at step 137, probe %s: stopped at step %ld: %.90s...\n", f.what,
                  probe_in_team ? "in the team" : "serial", b->step_count(), mb.c_str());
    }
}
