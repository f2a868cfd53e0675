// Toner carried by its carrier (populations[].carried_until_gap, dem/carried_toner.h): the
// reduced toner model. Checked on the inflow/outflow conveyor of test_particle_flow.cpp (a
// sleeve R = 2 mm at 0.2 m/s, a radial pull standing in for the magnet, developer fed at 90°
// and removed from 185°) with a drum (R = 1 mm) facing it at 135°, 0.3 mm from the sleeve
// (three beads), its surface moving with the sleeve's. A carrier riding the sleeve (top ~0.1 mm
// above it) comes within the release gap (0.25 mm) of the drum from ~128° to ~142°, and
// farther than twice the gap, where toner on it is taken back, beyond ~153°. The drum is past
// where the fed carriers land (~105°): a 100 µm carrier falling onto a released 17 µm toner
// would crush these soft test materials.
//
//  * the inflow's carriers bring their toner as mass and charge, no toner particle exists
//    upstream of the drum, every carrier just past it has released its toner, and beyond
//    ~153° no toner particle touches a carrier: the carriers took back what they held;
//  * toner is conserved to the particle and to rounding in mass: created = resolved + carried
//    + removed, each as count and mass (the outflow counts the toner a carrier takes out);
//  * a release places each toner touching its carrier, overlapping nothing, moving with the
//    carrier's surface; the carrier keeps exactly its own mass; charge is conserved exactly;
//  * a restart in the middle continues bit-identically (the carried arrays and the release's
//    random stream are in the checkpoint);
//  * the inflow brings each carrier with minus the charge of its toner (the developer fed is
//    neutral) and each toner with the population's q/m distribution, carried or not;
//  * the validation refuses it where it cannot apply.
#include "tests/dem/dem_test_scenes.h"
#include "dem/carried_toner.h"
#include "dem/particle_flow.h"
#include "tests/case_error.h"
#include "tests/dem/box_developer.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

constexpr double deg = M_PI / 180.0;
constexpr double sleeve_radius = 2e-3, drum_gap = 0.3e-3, release_gap = 0.25e-3;

Material material(const std::string &name, double E, double rho, double friction)
{
  Material m = elastic_material(name, E, 0.3, rho);
  m.friction = friction;
  m.damping = 0.6;
  return m;
}

// The conveyor with a drum and a toner population of 3 % riding its carriers.
Case developer_conveyor()
{
  Case c = single_species_case(material("carrier", 1e7, 2200, 0.5));
  c.scene = "roller";
  Population &carrier = c.populations[0];
  carrier.name = "carrier";
  carrier.kind = ParticleKind::carrier;
  carrier.diameter_mean = 100e-6;
  carrier.diameter_std = 10e-6;
  carrier.counter_charge = true;
  Population toner;
  toner.name = "toner";
  toner.kind = ParticleKind::toner;
  toner.material = "toner";
  toner.diameter_mean = 20e-6;
  toner.diameter_std = 2e-6;
  toner.concentration = 0.03;
  toner.charge_to_mass = -30e-3;
  toner.charge_to_mass_std = 6e-3;
  toner.wrong_sign_fraction = 0.05;
  toner.carried_until_gap = release_gap;
  c.populations.push_back(toner);
  c.materials.push_back(material("toner", 1e7, 1100, 0.3));
  Sleeve s;
  s.radius = sleeve_radius;
  s.rpm = 100.0 * 60.0 / (2.0 * M_PI);
  c.sleeve = s;
  c.materials.push_back(material("sleeve", 5e10, 0.0, 0.5));
  c.drum.present = true;
  c.drum.radius = 1e-3;
  c.drum.gap = drum_gap;
  c.drum.angle = 135 * deg;
  c.drum.rpm = -0.2 / 1e-3 * 60.0 / (2.0 * M_PI); // its surface moves with the sleeve's (0.2 m/s)
  c.materials.push_back(material("drum", 5e10, 0.0, 0.35));
  c.dem.periodic_length = 1e-3;
  c.dem.seed = 5;
  c.flow.inflow_areal_mass = 0.05;
  c.flow.inflow_angle = 90 * deg;
  c.flow.inflow_layer_height = 0.2e-3;
  c.flow.interval = 20e-6;
  c.flow.outflow_angle = 185 * deg;
  c.flow.outflow_width = 60 * deg;
  return c;
}

std::unique_ptr<DemSystem> make(const Case &c, double pull = 300.0)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<RadialPull>(pull));
  sys->set_particle_exchange(std::make_unique<ParticleFlow>(c, *sys));
  sys->initialize();
  return sys;
}

// The roller angle in [0, 2π) (the outflow is at 185°).
double roller_angle(const ParticleState &s, std::size_t k)
{
  const double a = std::atan2(s.y[k], s.x[k]);
  return a < 0.0 ? a + 2.0 * M_PI : a;
}

// The carried arrays and the masses and charges, by id (for the restart comparison).
std::vector<double> carried_by_id(const DemSystem &sys)
{
  const ParticleState &p = sys.particles();
  std::map<std::int32_t, std::size_t> by_id;
  for (std::size_t k = 0; k < p.size(); ++k)
    by_id[p.id[k]] = k;
  std::vector<double> out;
  for (const auto &[id, k] : by_id)
    for (double v : {static_cast<double>(p.carried_count[k]), p.carried_mass[k], p.carried_charge[k], p.mass[k],
                     p.inv_inertia[k], p.charge[k]})
      out.push_back(v);
  return out;
}

} // namespace

TEST(CarriedToner, TheConveyorReleasesAtTheDrumTakesBackBeyondAndConservesTonerToTheParticle)
{
  omp_set_num_threads(1);
  const Case c = developer_conveyor();
  auto sys = make(c);
  sys->advance(std::lround(21e-3 / sys->time_step())); // 1.3 transits from the inflow to the outflow
  const auto &flow = *static_cast<const ParticleFlow *>(sys->particle_exchange());
  const ParticleState &s = sys->particles();
  long resolved = 0, carried = 0, upstream = 0, upstream_bare = 0, past = 0, past_carrying = 0;
  long beyond = 0, beyond_carrying = 0, beyond_on_carriers = 0;
  double resolved_mass = 0.0, carried_mass = 0.0, upstream_toner = 0.0;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    const double a = roller_angle(s, k);
    if (s.species[k] == 1)
    {
      ++resolved;
      resolved_mass += s.mass[k];
      upstream_toner += a < 120 * deg;
      if (a > 160 * deg)
        for (std::size_t j = 0; j < s.size(); ++j)
          if (s.species[j] == 0)
          {
            double dz = s.z[k] - s.z[j];
            dz -= 1e-3 * std::round(dz / 1e-3);
            const double g = std::sqrt(std::pow(s.x[k] - s.x[j], 2) + std::pow(s.y[k] - s.y[j], 2) + dz * dz) -
                             s.radius[k] - s.radius[j];
            if (g < 0.02 * s.radius[k])
            {
              ++beyond_on_carriers;
              break;
            }
          }
      continue;
    }
    carried += s.carried_count[k];
    carried_mass += s.carried_mass[k];
    if (a < 120 * deg)
    {
      ++upstream;
      upstream_bare += s.carried_count[k] == 0;
    }
    if (a > 144 * deg && a < 150 * deg)
    {
      ++past;
      past_carrying += s.carried_count[k] > 0;
    }
    if (a > 160 * deg)
    {
      ++beyond;
      beyond_carrying += s.carried_count[k] > 0;
    }
  }
  const auto *release = flow.release();
  const long created = flow.source()->created_count()[1], removed = flow.sink()->removed_count()[1];
  const double created_mass = flow.source()->created_mass()[1], removed_mass = flow.sink()->removed_mass()[1];
  std::printf("toner created %ld (%.6g kg) = resolved %ld + carried %ld + removed %ld; released %ld, taken back %ld; "
              "carriers upstream %ld (bare %ld), just past the drum %ld (still carrying %ld), beyond 160 deg %ld "
              "(carrying again %ld; toner particles on carriers there %ld)\n",
              created, created_mass, resolved, carried, removed, release->released(), release->recaptured(), upstream,
              upstream_bare, past, past_carrying, beyond, beyond_carrying, beyond_on_carriers);
  ASSERT_GT(created, 800);
  EXPECT_GT(release->released(), 300);
  EXPECT_GT(release->recaptured(), 50);
  EXPECT_GT(removed, 100); // what carriers carried out, and free toner
  EXPECT_EQ(created, resolved + carried + removed);
  EXPECT_NEAR(resolved_mass + carried_mass + removed_mass, created_mass, 1e-12 * created_mass);
  // Where: upstream of the drum the carriers carry and no toner is a particle; just past it,
  // none carries; beyond, what stayed on a carrier is carried again.
  EXPECT_GT(upstream, 30);
  EXPECT_EQ(upstream_bare, 0);
  EXPECT_EQ(upstream_toner, 0.0);
  EXPECT_GT(past, 5);
  EXPECT_EQ(past_carrying, 0);
  EXPECT_GT(beyond, 10);
  EXPECT_GT(beyond_carrying, 0);
  EXPECT_EQ(beyond_on_carriers, 0);
}

TEST(CarriedToner, AReleasePlacesTheTonerOnItsCarrierAndConservesMassAndCharge)
{
  // Inserted developer (attached + carried) in a box under the drum, all within the gap.
  Case c = developer_conveyor();
  c.flow = FlowSettings{};
  c.populations[0].count = 40;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{-0.4e-3, 2.05e-3, 0.0}, Vec3{0.4e-3, 2.17e-3, 1e-3}};
  c.populations[1].attached = true;
  c.drum.angle = 90 * deg; // straight above the box (its surface at y = 2.3 mm): every carrier within 0.25 mm
  c.populations[1].carried_until_gap = 0.4e-3;
  DemSystem sys(c);
  sys.insert_particles();
  ParticleState s = sys.particles();
  ASSERT_EQ(s.size(), 40u); // the toner rides the carriers: no toner particle
  double own = 0.0, carried = 0.0, charge = 0.0, mass = 0.0, toner_charge = 0.0;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    EXPECT_GT(s.carried_count[k], 0);
    own += s.mass[k] - s.carried_mass[k];
    carried += s.carried_mass[k];
    charge += s.charge[k];
    mass += s.mass[k];
    toner_charge += s.carried_charge[k];
    // A carrier's moment of inertia: its solid sphere and the toner as a shell.
    EXPECT_NEAR(1.0 / s.inv_inertia[k],
                (0.4 * (s.mass[k] - s.carried_mass[k]) + 2.0 / 3.0 * s.carried_mass[k]) * s.radius[k] * s.radius[k],
                1e-12 / s.inv_inertia[k]);
  }
  const double toner_max = 1100 * M_PI / 6.0 * std::pow(26e-6, 3);
  EXPECT_NEAR(carried, 0.03 * own, toner_max);
  EXPECT_LT(toner_charge, 0.0);
  EXPECT_NEAR(charge, 0.0, 1e-9 * std::abs(toner_charge)); // the counter-charge makes it neutral

  // Moving and spinning carriers, released at once.
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    s.vx[k] = 0.1 + 0.01 * static_cast<double>(k);
    s.wz[k] = 1e3;
    s.wx[k] = -5e2;
  }
  const ParticleState before = s;
  CarriedTonerRelease release(c, sys.walls(), sys.box());
  ParticleState enter;
  release.release(s, 0.0, std::vector<char>(s.size(), 0), enter);
  ASSERT_GT(enter.size(), 100u);
  EXPECT_EQ(release.released(), static_cast<long>(enter.size()));
  double mass_after = 0.0, charge_after = 0.0;
  long still = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    mass_after += s.mass[k];
    charge_after += s.charge[k];
    still += s.carried_count[k];
    if (s.carried_count[k] == 0)
    {
      EXPECT_EQ(s.mass[k], before.mass[k] - before.carried_mass[k]); // exactly its own
      EXPECT_EQ(s.carried_mass[k], 0.0);
    }
  }
  for (std::size_t t = 0; t < enter.size(); ++t)
  {
    mass_after += enter.mass[t];
    charge_after += enter.charge[t];
  }
  EXPECT_EQ(still, 0) << "a sparse box: every toner finds room";
  EXPECT_NEAR(mass_after, mass, 1e-13 * mass);
  EXPECT_NEAR(charge_after, charge, 1e-12 * std::abs(toner_charge));
  // Each toner touches one carrier (periodic along z, 1 mm), overlaps nothing, moves with its surface.
  auto gap_to = [](const ParticleState &a, std::size_t i, const ParticleState &b, std::size_t j) {
    double dz = a.z[i] - b.z[j];
    dz -= 1e-3 * std::round(dz / 1e-3);
    return std::sqrt(std::pow(a.x[i] - b.x[j], 2) + std::pow(a.y[i] - b.y[j], 2) + dz * dz) - a.radius[i] - b.radius[j];
  };
  long wrong_sign = 0;
  for (std::size_t t = 0; t < enter.size(); ++t)
  {
    std::size_t on = s.size();
    for (std::size_t k = 0; k < s.size(); ++k)
    {
      const double g = gap_to(enter, t, s, k);
      EXPECT_GT(g, -1e-12);
      if (std::abs(g) < 1e-6 * enter.radius[t])
        on = k;
    }
    ASSERT_LT(on, s.size()) << "toner " << t << " touches no carrier";
    for (std::size_t u = t + 1; u < enter.size(); ++u)
      EXPECT_GT(gap_to(enter, t, enter, u), -1e-12);
    double rz = enter.z[t] - s.z[on];
    rz -= 1e-3 * std::round(rz / 1e-3);
    const Vector3 r{enter.x[t] - s.x[on], enter.y[t] - s.y[on], rz};
    const Vector3 u = s.velocity(on) + cross(s.angular_velocity(on), r);
    EXPECT_NEAR(enter.vx[t], u.x, 1e-12);
    EXPECT_NEAR(enter.vy[t], u.y, 1e-12);
    EXPECT_NEAR(enter.vz[t], u.z, 1e-12);
    wrong_sign += enter.charge[t] > 0.0;
  }
  // The population's q/m distribution, wrong-sign fraction (5 %) included.
  EXPECT_GT(wrong_sign, 0);
  EXPECT_LT(wrong_sign, static_cast<long>(enter.size()) / 5);
}

TEST(CarriedToner, RestartInTheMiddleContinuesBitIdentically)
{
  omp_set_num_threads(1);
  const Case c = developer_conveyor();
  const std::string path = (magbrush::testing::test_temp_dir("dem_carried_restart") / "restart.bin").string();
  auto a = make(c);
  const long half = std::lround(7.1e-3 / a->time_step()), rest = std::lround(3e-3 / a->time_step());
  a->advance(half);
  const long released_before = static_cast<const ParticleFlow *>(a->particle_exchange())->release()->released();
  a->write_checkpoint(path);
  a->advance(rest);

  DemSystem b(c);
  b.add_force_term(std::make_unique<RadialPull>(300.0));
  b.set_particle_exchange(std::make_unique<ParticleFlow>(c, b));
  b.read_checkpoint(path);
  b.advance(rest);
  const auto *fa = static_cast<const ParticleFlow *>(a->particle_exchange());
  const auto *fb = static_cast<const ParticleFlow *>(b.particle_exchange());
  std::printf("released %ld before the checkpoint, %ld at the end\n", released_before, fa->release()->released());
  EXPECT_GT(released_before, 0);
  EXPECT_GT(fa->release()->released(), released_before); // releases on both sides of it
  EXPECT_EQ(fa->release()->released(), fb->release()->released());
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
  EXPECT_TRUE(bit_identical(carried_by_id(*a), carried_by_id(b)));
  std::filesystem::remove(path);
}

TEST(CarriedToner, TheFedDeveloperIsNeutralCarrierByCarrierAndItsTonerHasTheQmDistribution)
{
  // The inflow's charges, toner resolved (no carrying) and carried: each carrier brings minus
  // the charge of its toner, each toner the population's q/m (mean -30, spread 6 uC/g, 5 %
  // wrong sign). An 8 mm slab for 0.8 ms without the pull: ~50 carriers fed, each moving on
  // as the sleeve launched it, nothing collides (a carrier landing on the sleeve would crush
  // the soft test toner under it), nothing comes near the drum or the outflow.
  for (const double gap : {0.0, release_gap})
  {
    omp_set_num_threads(1);
    Case c = developer_conveyor();
    c.populations[1].carried_until_gap = gap;
    c.dem.periodic_length = 8e-3;
    auto sys = make(c, 0.0);
    sys->advance(std::lround(0.8e-3 / sys->time_step()));
    const ParticleState &s = sys->particles();
    double total = 0.0, scale = 0.0, sum_qm = 0.0, sum_qm2 = 0.0;
    long toner = 0, wrong = 0, carried = 0;
    for (std::size_t k = 0; k < s.size(); ++k)
    {
      total += s.charge[k];
      scale += std::abs(s.charge[k]) + std::abs(s.carried_charge[k]);
      carried += s.carried_count[k];
      if (s.species[k] != 1)
        continue;
      const double qm = s.charge[k] / s.mass[k];
      ++toner;
      wrong += qm > 0.0;
      if (qm < 0.0)
      {
        sum_qm += qm;
        sum_qm2 += qm * qm;
      }
    }
    std::printf("release gap %.0f um: %zu particles, %ld toner (%ld wrong sign), %ld carried; net charge %.3g of %.3g C\n",
                gap * 1e6, s.size(), toner, wrong, carried, total, scale);
    ASSERT_GT(scale, 0.0);
    EXPECT_LT(std::abs(total), 1e-12 * scale);
    if (gap > 0.0)
    {
      EXPECT_EQ(toner, 0);
      EXPECT_GT(carried, 300);
      continue;
    }
    ASSERT_GT(toner, 300);
    EXPECT_GT(wrong, 0);
    EXPECT_LT(wrong, toner / 8);
    const long right = toner - wrong;
    const double mean = sum_qm / static_cast<double>(right);
    const double sd = std::sqrt(sum_qm2 / static_cast<double>(right) - mean * mean);
    EXPECT_NEAR(mean, -30e-3, 1.5e-3); // C/kg (uC/g = 1e-3 C/kg)
    EXPECT_NEAR(sd, 6e-3, 1.5e-3);
  }
}

namespace {
std::string error_of(const std::string &yaml) { return magbrush::testing::case_error_of(yaml, "developer.yaml"); }
} // namespace

TEST(CarriedToner, TheValidationRefusesItWhereItCannotApply)
{
  using magbrush::testing::box_developer;
  // No drum to release at.
  const std::string no_drum = error_of(box_developer("attached: true, carried_until_gap: 10 um"));
  EXPECT_NE(no_drum.find("populations.toner.carried_until_gap"), std::string::npos) << no_drum;
  EXPECT_NE(no_drum.find("no drum"), std::string::npos) << no_drum;
  // Toner by count: nothing rides a carrier.
  std::string count = box_developer("insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]], carried_until_gap: 10 um");
  count.replace(count.find("concentration: 5 %"), 18, "count: 100");
  const std::string by_count = error_of(count);
  EXPECT_NE(by_count.find("only toner given by a concentration"), std::string::npos) << by_count;
  // In a box, neither attached nor fed.
  const std::string loose =
      error_of(box_developer("insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]], carried_until_gap: 10 um"));
  EXPECT_NE(loose.find("set attached: true"), std::string::npos) << loose;
  // A negative gap.
  const std::string negative = error_of(box_developer("attached: true, carried_until_gap: -1 um"));
  EXPECT_NE(negative.find("carried_until_gap"), std::string::npos) << negative;
}
