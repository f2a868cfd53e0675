// Van der Waals adhesion in the contact law (dem/contact_law.h, HamakerAdhesion):
//  * the Derjaguin forms against Hamaker's exact sphere–sphere and sphere–plane forces: the
//    relative error is z/R* to first order, and the test asserts that bound;
//  * the engine applies it between particles and against walls, across a gap up to the
//    range and not beyond (the neighbour list and the wall detection reach that far);
//  * pull-off: a toner on a plate, and on a fixed carrier, in a slowly ramped field detaches
//    at E = F0 / q;
//  * the Coulomb limit sees the adhesion: a toner pushed sideways slides at μ (load + F0);
//  * 1 vs 2 threads give the same bits, and so does a restart; the adhesive kernel with A = 0
//    gives the values of the adhesion-free one;
//  * the case input: combining rule, per-pair override, and the errors for a missing partner
//    constant, an unknown material and a wrong unit; the Kweon case gives every pair its
//    constant.
#include "tests/dem/adhesion_scenes.h"
#include "tests/dem/dem_test_scenes.h"
#include "tests/test_temp_dir.h"

#include "dem/contact_parameters.h"
#include "dem/dem_system.h"
#include "dem/force_term.h"
#include "dem/pair_kernel.h"

#include "case/case_parser.h"
#include "dem/wall_contacts.h"
#include "geometry/wall_primitives.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();

// Hamaker's exact attraction between two spheres at centre distance d (Hamaker 1937):
//   U = −A/6 [2R₁R₂/P + 2R₁R₂/M + ln(P/M)],  P = d² − (R₁+R₂)²,  M = d² − (R₁−R₂)²,
//   F = dU/dd = (A/6) 2d [2R₁R₂/P² + 2R₁R₂/M² − 1/P + 1/M]   (attractive magnitude).
// P is written as z (2(R₁+R₂) + z) so that small gaps lose no digits.
long double exact_sphere_sphere(long double A, long double R1, long double R2, long double z)
{
  const long double d = R1 + R2 + z;
  const long double P = z * (2.0L * (R1 + R2) + z), M = d * d - (R1 - R2) * (R1 - R2);
  return A / 6.0L * 2.0L * d * (2.0L * R1 * R2 / (P * P) + 2.0L * R1 * R2 / (M * M) - 1.0L / P + 1.0L / M);
}

// Sphere–plane (the limit R₂ → ∞): U = −A/6 [R/z + R/(z+2R) + ln(z/(z+2R))],
//   F = (A/6) [R/z² + R/(z+2R)² − 1/z + 1/(z+2R)].
long double exact_sphere_plane(long double A, long double R, long double z)
{
  return A / 6.0L * (R / (z * z) + R / ((z + 2 * R) * (z + 2 * R)) - 1.0L / z + 1.0L / (z + 2 * R));
}

} // namespace

TEST(Adhesion, DerjaguinSphereSphereAgreesWithHamakerToFirstOrderInGapOverRadius)
{
  // The Derjaguin force exceeds the exact one by the relative amount z/R* to first order
  // (for any radius ratio): assert z/R* (1 − z/R*) ≤ error ≤ z/R* (1 + z/R*) for z/R* ≤ 0.1.
  const double A = 1e-19;
  for (const auto &[R1, R2] : {std::pair{3.5e-6, 3.5e-6}, std::pair{3.5e-6, 25e-6}, std::pair{50e-9, 50e-9}})
  {
    const double Rs = R1 * R2 / (R1 + R2);
    for (const double zr : {1e-4, 1e-3, 1e-2, 0.1})
    {
      const double z = zr * Rs;
      const double model = HamakerAdhesion::force(A, HamakerAdhesion::radius(R1, inf, R2, inf), z, 0.0);
      const double err = static_cast<double>(model / exact_sphere_sphere(A, R1, R2, z) - 1.0L);
      std::printf("sphere-sphere R1 %.3g m R2 %.3g m  z/R* %.0e: Derjaguin/exact - 1 = %.6e (z/R* %.0e)\n", R1, R2,
                  zr, err, zr);
      EXPECT_GE(err, zr * (1.0 - zr)) << R1 << " " << R2 << " " << zr;
      EXPECT_LE(err, zr * (1.0 + zr)) << R1 << " " << R2 << " " << zr;
    }
  }
}

TEST(Adhesion, DerjaguinSpherePlaneAgreesWithHamakerToFirstOrderInGapOverRadius)
{
  const double A = 1e-19, R = 3.5e-6;
  for (const double zr : {1e-4, 1e-3, 1e-2, 0.1})
  {
    const double z = zr * R;
    const double model = HamakerAdhesion::force(A, HamakerAdhesion::wall_radius(R, inf, inf), z, 0.0);
    const double err = static_cast<double>(model / exact_sphere_plane(A, R, z) - 1.0L);
    std::printf("sphere-plane z/R %.0e: Derjaguin/exact - 1 = %.6e\n", zr, err);
    EXPECT_GE(err, zr * (1.0 - zr));
    EXPECT_LE(err, zr * (1.0 + zr));
  }
  // The asperity radius replaces the particle radius, and caps it.
  EXPECT_DOUBLE_EQ(HamakerAdhesion::wall_radius(R, 50e-9, inf), 50e-9);
  EXPECT_DOUBLE_EQ(HamakerAdhesion::wall_radius(20e-9, 50e-9, inf), 20e-9);
  EXPECT_DOUBLE_EQ(HamakerAdhesion::radius(R, 50e-9, R, 50e-9), 25e-9);
  // Floored at z0 (inside the gap z0 and throughout an overlap: F0), cut nowhere here.
  EXPECT_DOUBLE_EQ(HamakerAdhesion::force(A, R, -1e-9, 0.4e-9), A * R / (6 * 0.16e-18));
  EXPECT_DOUBLE_EQ(HamakerAdhesion::force(A, R, 0.2e-9, 0.4e-9), A * R / (6 * 0.16e-18));
  EXPECT_DOUBLE_EQ(HamakerAdhesion::range(0.4e-9, 0.01), 4e-9);
}

TEST(Adhesion, EngineAppliesItAcrossTheGapUpToTheRange)
{
  // Two toner at gap z and a toner above a plate at gap z: the force on each is A R/(6 z²)
  // (z ≥ z0), F0 for z < z0, zero beyond the range z0/√f = 4 nm.
  omp_set_num_threads(1);
  const Material t = toner_material();
  const double r = 3.5e-6, A_tt = t.hamaker, A_tp = std::sqrt(t.hamaker * 2e-19);
  for (const double z : {0.1e-9, 0.4e-9, 1e-9, 3.9e-9, 4.1e-9, 20e-9})
  {
    Case c = toner_case(false);
    add_plate(c);
    DemSystem sys(c);
    // A pair far above the plate, and one toner above the plate at gap z.
    sys.particles().add({0, 0, 1e-3}, r, t.density, 0, 0.0);
    sys.particles().add({2 * r + z, 0, 1e-3}, r, t.density, 0, 0.0);
    sys.particles().add({1e-3, 0, r + z}, r, t.density, 0, 0.0);
    sys.initialize();
    const auto &p = sys.particles();
    const auto &f = sys.forces();
    const double s = std::max(z, 0.4e-9);
    const double pair = z < 4e-9 ? A_tt * 25e-9 / (6 * s * s) : 0.0; // asperities in series: 25 nm
    const double wall = z < 4e-9 ? A_tp * 50e-9 / (6 * s * s) : 0.0;   // a flat plate: 50 nm
    for (std::size_t i = 0; i < p.size(); ++i)
    {
      const double expected = p.id[i] == 0 ? pair : p.id[i] == 1 ? -pair : -wall;
      const double got = p.id[i] == 2 ? f.fz[i] : f.fx[i];
      // The gap is a difference of positions ~1e-3 m apart from ~1e-6 m: round-off ε x/z.
      EXPECT_NEAR(got, expected, 1e-9 * std::abs(expected)) << "z " << z << " id " << p.id[i];
    }
    EXPECT_EQ(sys.particle_contacts(), 0); // held across a gap: no contact
  }
}

TEST(Adhesion, TonerLeavesThePlateAtTheFieldThatBalancesTheAdhesion)
{
  const PullOff r = pull_off(false, 160e-6);
  const double err = r.field / r.predicted - 1.0;
  std::printf("pull-off from the plate: E %.6g V/m, F0/q %.6g V/m, error %.3e (dt %.3g s)\n", r.field,
              r.predicted, err, r.dt);
  EXPECT_LE(std::abs(err), 1e-2);
  EXPECT_TRUE(r.flew_off);
}

TEST(Adhesion, TonerLeavesACarrierAtTheFieldThatBalancesTheAdhesion)
{
  const PullOff r = pull_off(true, 160e-6);
  const double err = r.field / r.predicted - 1.0;
  std::printf("pull-off from a carrier: E %.6g V/m, F0/q %.6g V/m, error %.3e (dt %.3g s)\n", r.field,
              r.predicted, err, r.dt);
  EXPECT_LE(std::abs(err), 1e-2);
  EXPECT_TRUE(r.flew_off);
}

TEST(Adhesion, CoulombLimitIncludesTheAdhesion)
{
  // A toner pressed on the plate by N and held by F0, pushed sideways by 3 μ (N + F0): it
  // slides, and the friction the plate feels is μ (N + F0), the elastic force that carries
  // load and adhesion (not μ N). Rotation is frozen (I × 1e9) so that it slides, not rolls.
  // Pushed by 0.9 μ (N + F0) it sticks.
  omp_set_num_threads(1);
  const double r = 3.5e-6, mu = 0.4, F0 = pull_off_force(std::sqrt(2e-19 * 1e-19), 50e-9), N = 0.5 * F0;
  for (const double push : {3.0, 0.9})
  {
    Case c = toner_case(false);
    add_plate(c);
    DemSystem sys(c);
    sys.particles().add({0, 0, r}, r, 1200, 0, 0.0);
    sys.add_force_term(std::make_unique<RampedField>(0.0, Vector3{}, Vector3{push * mu * (N + F0), 0, -N}));
    sys.initialize();
    sys.particles().inv_inertia[0] *= 1e-9;
    while (sys.time() < 5e-6)
      sys.step();
    const auto load = sys.wall_loads()[0];
    const double friction = load.force[0], limit = mu * (N + F0);
    std::printf("push %.1f mu (N + F0): friction on the plate %.6e N, mu (N + F0) %.6e N, ratio - 1 %.3e, "
                "normal load %.6e N (N %.6e), x %.3e m\n",
                push, friction, limit, friction / limit - 1.0, -load.force[2], N, sys.particles().x[0]);
    EXPECT_NEAR(-load.force[2], N, 1e-3 * N); // the plate carries the load; adhesion is internal
    if (push > 1.0)
    {
      EXPECT_NEAR(friction, limit, 1e-3 * limit);
      EXPECT_GT(sys.particles().vx[0], 0.0);
    }
    else
    {
      EXPECT_NEAR(friction, 0.9 * limit, 1e-3 * limit);
      EXPECT_LT(std::abs(sys.particles().x[0]), 1e-9); // stuck: the spring's stretch only
    }
  }
}

namespace {
// ~1200 toner and 40 carriers with adhesion, falling on an adhesive plate in a periodic box:
// contacts, pairs held across gaps, list rebuilds and sorting.
Case adhesive_packing_case()
{
  Case c = toner_case(true);
  c.populations[0].diameter_std = 1e-6;
  c.populations[0].count = 1200;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{0.3e-3, 0.3e-3, 0.02e-3}};
  c.populations[1].diameter_std = 5e-6;
  c.populations[1].count = 40;
  c.populations[1].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0.02e-3}, Vec3{0.3e-3, 0.3e-3, 0.2e-3}};
  c.dem.periodic_length_x = c.dem.periodic_length_y = 0.3e-3;
  c.dem.seed = 7;
  c.dem.toner_stiffness_factor = 0.01; // a 10× larger step: more happens in few steps
  add_plate(c);
  return c;
}

std::unique_ptr<DemSystem> make_adhesive_packing(const Case &c)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->insert_particles();
  auto &p = sys->particles();
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const double k = static_cast<double>(i);
    p.vx[i] = std::sin(1.3 * k);
    p.vy[i] = std::cos(2.1 * k);
    p.vz[i] = std::sin(0.7 * k);
  }
  sys->initialize();
  return sys;
}

std::vector<double> run_by_id(const Case &c, int threads, int steps, long &contacts)
{
  omp_set_num_threads(threads);
  auto sys = make_adhesive_packing(c);
  for (int k = 0; k < steps; ++k)
    sys->step();
  contacts = sys->particle_contacts();
  return state_by_id(*sys);
}
} // namespace

TEST(Adhesion, RestartContinuesBitIdentically)
{
  // Nothing of the adhesion outlives a step but the list's reach and the wall slots of
  // particles held across a gap: a restart continues with the same bits.
  omp_set_num_threads(1);
  const Case c = adhesive_packing_case();
  const std::string path = (magbrush::testing::test_temp_dir("adhesion_restart") / "restart.bin").string();
  auto a = make_adhesive_packing(c);
  for (int k = 0; k < 400; ++k)
    a->step();
  a->write_checkpoint(path);
  for (int k = 0; k < 400; ++k)
    a->step();
  DemSystem b(c);
  b.read_checkpoint(path);
  for (int k = 0; k < 400; ++k)
    b.step();
  const auto x = state_by_id(*a), y = state_by_id(b);
  EXPECT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(double)), 0);
  std::filesystem::remove(path);
}

TEST(Adhesion, OneAndTwoThreadsGiveIdenticalBits)
{
  const Case c = adhesive_packing_case();
  long contacts[2] = {0, 0};
  const auto a = run_by_id(c, 1, 1500, contacts[0]);
  const auto b = run_by_id(c, 2, 1500, contacts[1]);
  omp_set_num_threads(2);
  std::printf("adhesive packing: %zu particles, %ld contacts after 1500 steps\n", a.size() / state_values_per_particle, contacts[0]);
  EXPECT_GT(contacts[0], 20);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}

TEST(Adhesion, AdhesiveKernelWithoutHamakerGivesTheBitsOfTheAdhesionFreeKernel)
{
  // The same pairs through both instantiations of the pair kernel (the adhesive one with
  // A = 0): forces, torques and histories are equal, so adding adhesion leaves the contact
  // arithmetic untouched.
  const int n = 64;
  std::vector<double> x(n), y(n), z(n), v(3 * n), w(3 * n), radius(n), mass(n), invI(n);
  std::vector<std::int32_t> species(n, 0), owner, partner, image;
  for (int i = 0; i < n; ++i)
  {
    x[i] = 1e-5 * (i % 8);
    y[i] = 1e-5 * (i / 8);
    z[i] = 1e-7 * std::sin(i);
    radius[i] = 5.05e-6 + 1e-8 * std::cos(3 * i);
    mass[i] = 1200 * 4.18879 * radius[i] * radius[i] * radius[i];
    invI[i] = 1.0 / (0.4 * mass[i] * radius[i] * radius[i]);
    for (int k = 0; k < 3; ++k)
    {
      v[k * n + i] = 0.01 * std::sin(i + k);
      w[k * n + i] = 100.0 * std::cos(i * k);
    }
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
    {
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      if (dx * dx + dy * dy < 2.2e-10)
      {
        owner.push_back(i);
        partner.push_back(j);
        image.push_back(0);
      }
    }
  const std::size_t P = owner.size();
  double shift[3] = {0, 0, 0};
  double E = 1e9, G = 4e8, mu = 0.4, mur = 0.1, an = 0.5, at = 0.4, A = 0.0, ai = 5e-8, aj = 5e-8;
  std::vector<double> out[2];
  for (int adhesive = 0; adhesive < 2; ++adhesive)
  {
    std::vector<double> h(3 * P, 1e-9), f(3 * P), tj(3 * P), ti(3 * P);
    std::vector<std::int32_t> touching(P);
    const PairKernelData D{x.data(), y.data(), z.data(), v.data(), v.data() + n, v.data() + 2 * n, w.data(),
                           w.data() + n, w.data() + 2 * n, radius.data(), mass.data(), invI.data(), species.data(),
                           owner.data(), partner.data(), image.data(), shift, shift + 1, shift + 2, &E, &G, &mu,
                           &mur, &an, &at, 1, true, 1e-9, 0.5, h.data(), h.data() + P, h.data() + 2 * P,
                           f.data(), f.data() + P, f.data() + 2 * P, tj.data(), tj.data() + P, tj.data() + 2 * P,
                           touching.data(), &A, &ai, &aj, 0.4e-9, 4e-9, adhesive == 1};
    const RowTorques T{ti.data(), ti.data() + P, ti.data() + 2 * P};
    particle_pair_kernel(D, T, 0, static_cast<std::int64_t>(P));
    out[adhesive] = h;
    out[adhesive].insert(out[adhesive].end(), f.begin(), f.end());
    out[adhesive].insert(out[adhesive].end(), tj.begin(), tj.end());
    out[adhesive].insert(out[adhesive].end(), ti.begin(), ti.end());
  }
  long touching = 0;
  for (std::size_t p = 0; p < P; ++p)
    touching += out[0][3 * P + p] != 0.0;
  std::printf("%zu pairs, %ld with a contact force\n", P, touching);
  EXPECT_GT(touching, 20);
  // Equal values (a zero force may differ in its sign bit: −0 + 0 = +0).
  ASSERT_EQ(out[0].size(), out[1].size());
  long differ = 0;
  for (std::size_t k = 0; k < out[0].size(); ++k)
    differ += out[0][k] != out[1][k];
  EXPECT_EQ(differ, 0);
}

TEST(Adhesion, HamakerConstantsOfPairsAndTheirErrors)
{
  Case c = toner_case(true);
  add_plate(c);
  ContactTable t;
  t.build(c, {"toner", "carrier"}, {"plate"});
  // Combining rule √(A₁ A₂).
  EXPECT_DOUBLE_EQ(t.adhesion_pair(0, 1).hamaker, std::sqrt(1e-19 * 4e-19));
  EXPECT_DOUBLE_EQ(t.adhesion_pair(1, 0).hamaker, std::sqrt(1e-19 * 4e-19));
  EXPECT_DOUBLE_EQ(t.adhesion_wall(0, 0).hamaker, std::sqrt(1e-19 * 2e-19));
  EXPECT_DOUBLE_EQ(t.adhesion_pair(0, 0).asperity_j, 50e-9);
  EXPECT_TRUE(std::isinf(t.adhesion_pair(1, 1).asperity_i)); // carrier: its own radius
  EXPECT_DOUBLE_EQ(t.adhesion_range(), 4e-9);
  // A per-pair override.
  c.adhesion_pairs.push_back({"plate", "toner", 1.5e-19});
  t.build(c, {"toner", "carrier"}, {"plate"});
  EXPECT_DOUBLE_EQ(t.adhesion_wall(0, 0).hamaker, 1.5e-19);
  // A partner without a written constant: an error naming the pair and the key to write.
  Case missing = toner_case(true);
  missing.materials[1].hamaker = 0.0;
  missing.materials[1].hamaker_given = false; // the carrier says nothing
  try
  {
    t.build(missing, {"toner", "carrier"}, {});
    ADD_FAILURE() << "no error";
  }
  catch (const std::invalid_argument &e)
  {
    const std::string m = e.what();
    EXPECT_NE(m.find("adhesion between 'toner' and 'carrier'"), std::string::npos) << m;
    EXPECT_NE(m.find("materials.carrier.hamaker"), std::string::npos) << m;
  }
  // An explicit zero is accepted: no adhesion for that pair.
  missing.materials[1].hamaker_given = true;
  t.build(missing, {"toner", "carrier"}, {});
  EXPECT_EQ(t.adhesion_pair(0, 1).hamaker, 0.0);
  EXPECT_GT(t.adhesion_pair(0, 0).hamaker, 0.0);
  // Unknown material and duplicate pairs.
  Case bad = toner_case(false);
  bad.adhesion_pairs.push_back({"toner", "drum", 1e-19});
  EXPECT_THROW(t.build(bad, {"toner"}, {}), std::invalid_argument);
  bad.adhesion_pairs = {{"toner", "plate", 1e-19}, {"plate", "toner", 2e-19}};
  EXPECT_THROW(t.build(bad, {"toner"}, {}), std::invalid_argument);
  // Nothing sticks: no range, the adhesion-free kernel.
  Case none = toner_case(false, 0.0);
  none.materials[0].hamaker = 0.0;
  t.build(none, {"toner"}, {"plate"});
  EXPECT_FALSE(t.adhesive());
  EXPECT_EQ(t.adhesion_range(), 0.0);
}

TEST(Adhesion, CaseKeysParseAndNameTheirErrors)
{
  const std::string base = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml";
  std::ifstream in(base);
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  const Case c = parse_case_text(text + "adhesion_pairs:\n  - {material_a: carrier, material_b: drum, hamaker: 1.5e-19 J}\n",
                                 "t.yaml", {"materials.carrier.hamaker=1e-19 J", "materials.carrier.adhesion_radius=80 nm",
                                            "dem.adhesion_cutoff=0.3 nm"});
  ASSERT_EQ(c.adhesion_pairs.size(), 1u);
  EXPECT_EQ(c.adhesion_pairs[0].material_b, "drum");
  EXPECT_DOUBLE_EQ(c.adhesion_pairs[0].hamaker, 1.5e-19);
  EXPECT_TRUE(c.material("carrier").hamaker_given);
  EXPECT_FALSE(c.material("drum").hamaker_given);
  EXPECT_DOUBLE_EQ(c.material("carrier").adhesion_radius, 80e-9);
  EXPECT_DOUBLE_EQ(c.dem.adhesion_cutoff, 0.3e-9);
  try
  {
    parse_case_text(text + "adhesion_pairs:\n  - {material_a: carrier, material_b: drum, hamaker: 1.5e-19 m}\n", "t.yaml");
    ADD_FAILURE() << "no error";
  }
  catch (const std::exception &e)
  {
    const std::string m = e.what();
    EXPECT_NE(m.find("adhesion_pairs[0].hamaker"), std::string::npos) << m;
    EXPECT_NE(m.find("expected an energy"), std::string::npos) << m;
  }
}

TEST(Adhesion, TheKweonCaseGivesEveryPairItsHamakerConstant)
{
  // The development case sets Hamaker constants for the toner and every material it meets,
  // with 50 nm asperities: its contact table builds, and the toner's pull-off forces are
  // nN, not the µN of smooth 7 µm spheres. Its toner-carrier pair is set apart (35 nN, tens of
  // nN as measured): the carried toner model it uses assumes toner stays on its carrier.
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_development.yaml");
  std::vector<std::string> species;
  for (const auto &p : c.populations)
    species.push_back(p.material);
  const DemWalls walls(build_wall_primitives(c));
  ContactTable t;
  t.build(c, species, walls.materials());
  ASSERT_TRUE(t.adhesive());
  const int toner = species[0] == "toner" ? 0 : 1, carrier = 1 - toner;
  const double r_t = 0.5 * c.populations[static_cast<std::size_t>(toner)].diameter_mean;
  const double r_c = 0.5 * c.populations[static_cast<std::size_t>(carrier)].diameter_mean;
  const double z0 = t.adhesion_cutoff();
  const auto &tc = t.adhesion_pair(toner, carrier);
  const double F_tc = HamakerAdhesion::force(tc.hamaker, HamakerAdhesion::radius(r_t, tc.asperity_i, r_c, tc.asperity_j), 0.0, z0);
  std::printf("Kweon case: toner-carrier pull-off %.3g N (A %.3g J)\n", F_tc, tc.hamaker);
  for (std::size_t w = 0; w < walls.size(); ++w)
  {
    const auto &a = t.adhesion_wall(toner, static_cast<int>(w));
    const double F = HamakerAdhesion::force(a.hamaker, HamakerAdhesion::wall_radius(r_t, a.asperity_i, a.asperity_j), 0.0, z0);
    std::printf("Kweon case: toner-%s (%s) pull-off %.3g N (A %.3g J)\n", walls.name(w).c_str(),
                walls.material(w).c_str(), F, a.hamaker);
    EXPECT_LT(F, 1e-7);
  }
  EXPECT_GT(F_tc, 1e-8);
  EXPECT_LT(F_tc, 1e-7);
}
