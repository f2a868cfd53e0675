// Particles entering and leaving a running scene (DemSystem::exchange_particles and the
// scheduled ParticleExchange): the contact history of every surviving pair and wall contact
// is carried over bit for bit, a leaver's contacts vanish, newcomers start free under ids never
// used before; with an exchange that drains and rains particles every few steps, 1 and 2
// threads give the same bits, advance(n) gives the bits of n single steps, and a restart from
// a checkpoint in the middle continues bit-identically (the exchange's random stream and
// counters are in the checkpoint).
#include "tests/dem/dem_test_scenes.h"
#include "common/random_engine_state.h"
#include "dem/checkpoint_file.h"
#include "dem/force_terms/gravity.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

// ~1200 falling spheres (dem_test_scenes.h).
Case packing_case() { return falling_spheres_case(1200, 3e-3, 0.3e-3, 42); }

// A drain and a rain: every `every` steps the particles low in one corner (x < 0.6 mm,
// z < 0.15 mm) leave, and a few new ones (a seeded random stream) appear high above the
// packing, clear of every particle, falling at 0.3 m/s.
class DrainAndRain : public ParticleExchange
{
public:
  explicit DrainAndRain(long every) : every_(every), rng_(7) {}
  const char *name() const override { return "drain and rain"; }
  long interval_steps() const override { return every_; }
  void plan(ParticleState &s, double, std::vector<std::int32_t> &leave, ParticleState &enter) override
  {
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.x[i] < 0.6e-3 && s.z[i] < 0.15e-3)
        leave.push_back(static_cast<std::int32_t>(i));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 4; ++k)
    {
      const double r = 40e-6 + 20e-6 * u(rng_);
      const Vector3 p{3e-3 * u(rng_), 3e-3 * u(rng_), 1.2e-3 + 0.3e-3 * u(rng_)};
      // Clear of every particle (periodic images along x and y), with room to spare.
      auto apart = [&p](const Vector3 &q) {
        Vector3 d = q - p;
        d.x -= 3e-3 * std::round(d.x / 3e-3);
        d.y -= 3e-3 * std::round(d.y / 3e-3);
        return norm(d);
      };
      bool clear = true;
      for (std::size_t i = 0; i < s.size() && clear; ++i)
        clear = apart(s.position(i)) > r + s.radius[i] + 1e-4;
      for (std::size_t i = 0; i < enter.size() && clear; ++i)
        clear = apart(enter.position(i)) > r + enter.radius[i] + 1e-4;
      if (!clear)
        continue;
      enter.add(p, r, 2200, 0, 0.0);
      enter.vz.back() = -0.3;
      ++created_;
    }
  }
  void smallest_particles(ParticleState &out) const override { out.add({0, 0, 0}, 40e-6, 2200, 0, 0.0); }
  void write_state(CheckpointWriter &out) const override
  {
    put_random_engine(out, rng_);
    out.put(created_);
  }
  void read_state(CheckpointReader &in) override
  {
    get_random_engine(in, rng_);
    created_ = in.get<long>();
  }
  long created() const { return created_; }

private:
  long every_;
  std::mt19937_64 rng_;
  long created_ = 0;
};

std::unique_ptr<DemSystem> make_packing(const Case &c, long exchange_every)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  if (exchange_every > 0)
    sys->set_particle_exchange(std::make_unique<DrainAndRain>(exchange_every));
  sys->insert_particles();
  give_random_velocities(sys->particles(), 3); // contacts form within a few hundred steps
  sys->initialize();
  return sys;
}

// The touching pairs' ξ by (smaller id, larger id), oriented from the smaller id.
std::map<std::pair<int, int>, Vector3> pair_history(const DemSystem &s)
{
  std::map<std::pair<int, int>, Vector3> h;
  const auto &L = s.neighbour_list();
  const auto &p = s.particles();
  for (std::size_t q = 0; q < L.pairs(); ++q)
  {
    if (!L.touching[q])
      continue;
    const int a = p.id[static_cast<std::size_t>(L.owner[q])], b = p.id[static_cast<std::size_t>(L.partner[q])];
    const Vector3 xi{L.hist_x[q], L.hist_y[q], L.hist_z[q]};
    if (a < b)
      h[{a, b}] = xi;
    else
      h[{b, a}] = Vector3{-xi.x, -xi.y, -xi.z};
  }
  return h;
}

// The occupied wall slots' ξ by (id, wall).
std::map<std::pair<int, int>, Vector3> wall_history(const DemSystem &s)
{
  std::map<std::pair<int, int>, Vector3> h;
  const auto &p = s.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < WallContactSlots::per_particle; ++k)
    {
      const std::size_t slot = i * WallContactSlots::per_particle + static_cast<std::size_t>(k);
      if (s.wall_slots().wall(slot) >= 0)
        h[{p.id[i], s.wall_slots().wall(slot)}] = s.wall_slots().history(slot);
    }
  return h;
}

bool same_bits(const Vector3 &a, const Vector3 &b) { return std::memcmp(&a, &b, sizeof a) == 0; }

} // namespace

// A compressed simple-cubic stack (10 × 10 × 5 spheres of 100 µm at 99 µm spacing, periodic in
// x and y, between the stage and a lid) shaken with random velocities: every neighbour pair and every bottom
// sphere touches, and the tangential springs have stretched within a few hundred steps.
std::unique_ptr<DemSystem> make_lattice(const Case &c)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  auto &p = sys->particles();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double a = 99e-6;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i)
      {
        p.add({(i + 0.5) * a, (j + 0.5) * a, 49.5e-6 + k * a}, 50e-6, 2200, 0, 0.0);
        p.vx.back() = 0.05 * u(rng);
        p.vy.back() = 0.05 * u(rng);
        p.wz.back() = 500.0 * u(rng);
      }
  sys->initialize();
  return sys;
}

TEST(DemParticleExchange, SurvivingContactsKeepTheirHistoryBitForBit)
{
  omp_set_num_threads(1);
  Case c = packing_case();
  c.dem.periodic_length_x = c.dem.periodic_length_y = 10 * 99e-6;
  add_rigid_plane(c, {0, 0, 99e-6 + 4 * 99e-6}, {0, 0, -1}, 0.3, 0.35); // a lid: the stack stays compressed
  auto sys = make_lattice(c);
  sys->advance(300);
  const auto pairs_before = pair_history(*sys);
  const auto walls_before = wall_history(*sys);
  const std::int32_t next_id = sys->particles().next_id;
  // Leave: every particle with an id divisible by 5 (all of them in contact). Enter: 30
  // small spheres in the voids of the lattice, clear of everything.
  std::vector<std::int32_t> leave;
  std::vector<int> left_ids;
  const auto &p = sys->particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.id[i] % 5 == 0)
    {
      leave.push_back(static_cast<std::int32_t>(i));
      left_ids.push_back(p.id[i]);
    }
  ParticleState enter;
  for (int k = 0; k < 30; ++k)
    enter.add({99e-6 * (k % 10 + 1), 99e-6 * (3 * (k / 10) + 1), 49.5e-6 + 1.5 * 99e-6}, 20e-6, 2200, 0, 0.0); // in voids
  const std::size_t n_before = p.size();
  sys->exchange_particles(leave, enter);

  const auto pairs_after = pair_history(*sys);
  const auto walls_after = wall_history(*sys);
  auto left = [&](int id) { return id % 5 == 0 && id < next_id; };
  long kept_pairs = 0, kept_walls = 0, pairs_with_leavers = 0;
  for (const auto &[key, xi] : pairs_before)
  {
    if (left(key.first) || left(key.second))
    {
      ++pairs_with_leavers;
      EXPECT_EQ(pairs_after.count(key), 0u) << "a contact of a particle that left survived";
      continue;
    }
    const auto it = pairs_after.find(key);
    ASSERT_NE(it, pairs_after.end()) << "the contact " << key.first << "-" << key.second << " was lost";
    EXPECT_TRUE(same_bits(it->second, xi)) << "the history of " << key.first << "-" << key.second << " changed";
    ++kept_pairs;
  }
  EXPECT_EQ(pairs_after.size(), static_cast<std::size_t>(kept_pairs)) << "no contact may appear from nowhere";
  for (const auto &[key, xi] : walls_before)
  {
    if (left(key.first))
    {
      EXPECT_EQ(walls_after.count(key), 0u);
      continue;
    }
    const auto it = walls_after.find(key);
    ASSERT_NE(it, walls_after.end()) << "the wall contact of " << key.first << " was lost";
    EXPECT_TRUE(same_bits(it->second, xi));
    ++kept_walls;
  }
  EXPECT_EQ(walls_after.size(), static_cast<std::size_t>(kept_walls));
  std::printf("exchange: %zu particles, %zu left, 30 entered; %ld pair contacts kept bit for bit, %ld vanished with "
              "a leaver; %ld wall contacts kept\n",
              n_before, leave.size(), kept_pairs, pairs_with_leavers, kept_walls);
  EXPECT_GT(kept_pairs, 600);
  EXPECT_GT(pairs_with_leavers, 200);
  EXPECT_GT(kept_walls, 100);
  long nonzero = 0;
  for (const auto &[key, xi] : pairs_after)
    nonzero += norm(xi) > 0.0;
  EXPECT_GT(nonzero, 500) << "the test needs contacts with a stretched tangential spring";
  // Ids: the leavers' are gone, the newcomers' are new and never reused.
  const auto &q = sys->particles();
  EXPECT_EQ(q.size(), n_before - leave.size() + 30);
  std::vector<int> ids(q.id.begin(), q.id.end());
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end()) << "duplicate ids";
  for (int id : left_ids)
    EXPECT_FALSE(std::binary_search(ids.begin(), ids.end(), id));
  for (int k = 0; k < 30; ++k)
    EXPECT_TRUE(std::binary_search(ids.begin(), ids.end(), next_id + k));
  EXPECT_EQ(q.next_id, next_id + 30);
  // The run goes on; a second exchange names ids after all earlier ones.
  sys->advance(50);
  ParticleState more;
  more.add({99e-6 * 5, 99e-6 * 8, 49.5e-6 + 2.5 * 99e-6}, 20e-6, 2200, 0, 0.0);
  sys->exchange_particles({0}, more);
  EXPECT_EQ(sys->particles().next_id, next_id + 31);
  EXPECT_EQ(sys->particles_entered(), 31);
  EXPECT_EQ(sys->particles_left(), static_cast<long>(leave.size()) + 1);
}

// An exchange at which nobody leaves or enters changes nothing: the particles keep their order
// and the neighbour list is not rebuilt, so the run gives the bits of the same run without an
// exchange (a fed scene exchanges every few µs, mostly with nobody at its doors).
class EmptyDoors : public ParticleExchange
{
public:
  const char *name() const override { return "empty doors"; }
  long interval_steps() const override { return 3; }
  void plan(ParticleState &, double, std::vector<std::int32_t> &, ParticleState &) override { ++plans; }
  void smallest_particles(ParticleState &out) const override { out.add({0, 0, 0}, 40e-6, 2200, 0, 0.0); }
  void write_state(CheckpointWriter &) const override {}
  void read_state(CheckpointReader &) override {}
  long plans = 0;
};

TEST(DemParticleExchange, AnEmptyExchangeNeitherReordersNorRebuilds)
{
  omp_set_num_threads(2);
  const Case c = packing_case();
  auto plain = make_packing(c, 0);
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  auto doors = std::make_unique<EmptyDoors>();
  const EmptyDoors *seen = doors.get();
  sys->set_particle_exchange(std::move(doors));
  sys->insert_particles();
  give_random_velocities(sys->particles(), 3);
  sys->initialize();
  plain->advance(900);
  sys->advance(900);
  EXPECT_EQ(seen->plans, 300);
  EXPECT_GT(plain->neighbour_rebuilds(), 1); // the list did expire meanwhile: the count is a check
  EXPECT_EQ(sys->neighbour_rebuilds(), plain->neighbour_rebuilds());
  EXPECT_EQ(sys->particles_entered(), 0);
  EXPECT_EQ(sys->particles_left(), 0);
  EXPECT_TRUE(bit_identical(state_by_id(*sys), state_by_id(*plain)));
}

TEST(DemParticleExchange, OneAndTwoThreadsGiveIdenticalBits)
{
  const Case c = packing_case();
  std::vector<double> result[2];
  long entered = 0, left = 0;
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    auto sys = make_packing(c, 20);
    sys->advance(1200);
    result[threads - 1] = state_by_id(*sys);
    entered = sys->particles_entered();
    left = sys->particles_left();
  }
  omp_set_num_threads(2);
  std::printf("exchange every 20 steps, 1200 steps: %ld entered, %ld left\n", entered, left);
  EXPECT_GT(entered, 100);
  EXPECT_GT(left, 20);
  EXPECT_TRUE(bit_identical(result[0], result[1]));
}

TEST(DemParticleExchange, AdvanceGivesTheBitsOfSingleSteps)
{
  omp_set_num_threads(2);
  const Case c = packing_case();
  auto a = make_packing(c, 20);
  auto b = make_packing(c, 20);
  a->advance(437);
  for (int k = 0; k < 437; ++k)
    b->step();
  EXPECT_GT(a->particles_entered(), 50);
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(*b)));
}

TEST(DemParticleExchange, RestartInTheMiddleContinuesBitIdentically)
{
  omp_set_num_threads(1);
  const Case c = packing_case();
  const std::string path = (magbrush::testing::test_temp_dir("dem_exchange_restart") / "restart.bin").string();
  auto a = make_packing(c, 20);
  a->advance(610); // not a multiple of the exchange interval
  a->write_checkpoint(path);
  a->advance(590);

  DemSystem b(c);
  b.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  auto rain = std::make_unique<DrainAndRain>(20);
  const DrainAndRain *rain_b = rain.get();
  b.set_particle_exchange(std::move(rain));
  b.read_checkpoint(path);
  b.advance(590);
  EXPECT_EQ(a->step_count(), b.step_count());
  EXPECT_EQ(a->particles_entered(), b.particles_entered());
  EXPECT_EQ(a->particles_left(), b.particles_left());
  EXPECT_EQ(static_cast<const DrainAndRain *>(a->particle_exchange())->created(), rain_b->created());
  EXPECT_GT(a->particles_entered(), 100);
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
  std::filesystem::remove(path);
}

TEST(DemParticleExchange, RestartWithoutTheExchangeIsRefused)
{
  omp_set_num_threads(1);
  const Case c = packing_case();
  const std::string path = (magbrush::testing::test_temp_dir("dem_exchange_refused") / "restart.bin").string();
  auto a = make_packing(c, 20);
  a->advance(30);
  a->write_checkpoint(path);
  DemSystem b(c);
  b.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  try
  {
    b.read_checkpoint(path);
    FAIL() << "a checkpoint with a particle exchange was read by a run without one";
  }
  catch (const std::runtime_error &e)
  {
    EXPECT_NE(std::string(e.what()).find("drain and rain"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}
