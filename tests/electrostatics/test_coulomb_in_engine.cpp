// The Coulomb term inside the engine: the registry switches it on for a charged population
// (and the conductor images off in a box scene without sleeve or drum), and a run with a held
// far field restarts from a DemSystem checkpoint bit for bit, also while the fast few charges
// are renewed alone between whole evaluations (the same bits on one and two threads).
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/held_forces.h"

#include "case/case_parser.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <omp.h>
#include <random>

using namespace magbrush;

namespace {
const char *scene = R"(
name: charged_toner
scene: box
materials:
  toner: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 1000 kg/m^3, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
populations:
  - {name: toner, kind: toner, material: toner, diameter: 8 um, count: 1, charge_to_mass: -30 uC/g, insert_box: [[0 mm, 0 mm, 0 mm], [0.3 mm, 0.3 mm, 0.3 mm]]}
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
dem: {time_step: 2e-9 s, periodic_length_x: 0.3 mm, gravity: [0, 0, 0]}
electric: {enabled: false, coulomb_refresh: 20 ns}
)";

// 392 toner with charges of both signs (net neutral) on a jittered 37.5 µm lattice, at rest.
void fill(dem::DemSystem &system)
{
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  auto &p = system.particles();
  const double a = 0.3e-3 / 8;
  int k = 0;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 7; ++j)
      for (int l = 0; l < 7; ++l, ++k)
        p.add({a * (i + 0.5 + u(rng)), a * (j + 0.5 + u(rng)), a * (l + 0.5 + u(rng))}, 4e-6, 1000.0, 0,
              k % 2 ? 3e-15 : -3e-15);
}

// `b` (a system of case c) with the particles `fill_it` places and the case's force terms,
// restored from `checkpoint` and advanced by `steps`.
void restore_and_advance(dem::DemSystem &b, const Case &c, void (*fill_it)(dem::DemSystem &),
                         const std::string &checkpoint, long steps)
{
  fill_it(b);
  dem::add_case_force_terms(b, c);
  b.initialize();
  b.read_checkpoint(checkpoint);
  b.advance(steps);
}
} // namespace

TEST(CoulombInEngine, RegistryChoosesTheTermsAndRestartIsBitForBit)
{
  const Case c = parse_case_text(scene, "charged_toner.yaml");
  dem::DemSystem a(c);
  fill(a);
  const auto choices = dem::add_case_force_terms(a, c);
  bool coulomb = false, images = false;
  for (const auto &choice : choices)
  {
    if (choice.name == "Coulomb")
      coulomb = choice.on;
    if (choice.name == "conductor images")
    {
      images = choice.on;
      EXPECT_EQ(choice.reason, "the scene has no sleeve or drum");
    }
  }
  EXPECT_TRUE(coulomb);
  EXPECT_FALSE(images);
  a.initialize();
  a.advance(25); // the far field refreshed every 10 steps: 5 steps into a held interval
  const auto path = (magbrush::testing::test_temp_dir("coulomb_engine") / "checkpoint.bin").string();
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  a.write_checkpoint(path);
  a.advance(20);

  dem::DemSystem b(c);
  restore_and_advance(b, c, fill, path, 20);
  const auto &pa = a.particles(), &pb = b.particles();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_EQ(std::memcmp(pa.x.data(), pb.x.data(), pa.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(pa.vx.data(), pb.vx.data(), pa.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(pa.vz.data(), pb.vz.data(), pa.size() * sizeof(double)), 0);
  // The charges moved: the Coulomb forces acted.
  double speed = 0.0;
  for (std::size_t i = 0; i < pa.size(); ++i)
    speed = std::max(speed, std::abs(pa.vx[i]) + std::abs(pa.vy[i]) + std::abs(pa.vz[i]));
  EXPECT_GT(speed, 0.0);
}

namespace {
// The lattice with a few fast toner (every 25th at 2 m/s, the others at 2 cm/s): at the case's
// 20 nm hold and 2 ns steps the fast ones move the hold distance every 5 steps, the others
// every 500.
void fill_with_fast_few(dem::DemSystem &system)
{
  fill(system);
  auto &p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const double speed = i % 25 == 0 ? 2.0 : 0.02, a = static_cast<double>(i);
    p.vx[i] = speed * std::cos(a);
    p.vy[i] = speed * std::sin(a) * std::cos(0.7 * a);
    p.vz[i] = speed * std::sin(a) * std::sin(0.7 * a);
  }
}

const dem::HeldForces &held_coulomb(const dem::DemSystem &system)
{
  for (const auto &term : system.force_terms())
    if (const auto *held = dynamic_cast<const dem::HeldForces *>(term.get()); held && held->name() == std::string("Coulomb"))
      return *held;
  throw std::runtime_error("no held Coulomb term");
}
} // namespace

TEST(CoulombInEngine, TheFewRenewedAloneRestartBitForBitOnOneAndTwoThreads)
{
  // The far field refreshed every 1 µs (500 steps): within these 80 steps only the holds decide.
  std::string text = scene;
  text.replace(text.find("coulomb_refresh: 20 ns"), 22, "coulomb_refresh: 1 us");
  const Case c = parse_case_text(text, "charged_toner.yaml");
  const auto path = (magbrush::testing::test_temp_dir("coulomb_engine_renewed") / "checkpoint.bin").string();
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::vector<double> x[2];
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    dem::DemSystem a(c);
    fill_with_fast_few(a);
    dem::add_case_force_terms(a, c);
    a.initialize();
    a.advance(40);
    a.write_checkpoint(path);
    a.advance(40);
    dem::DemSystem b(c);
    restore_and_advance(b, c, fill_with_fast_few, path, 40);
    const auto &pa = a.particles(), &pb = b.particles();
    ASSERT_EQ(pa.size(), pb.size());
    EXPECT_EQ(std::memcmp(pa.x.data(), pb.x.data(), pa.size() * sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(pa.vx.data(), pb.vx.data(), pa.size() * sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(pa.vy.data(), pb.vy.data(), pa.size() * sizeof(double)), 0);
    // The fast few were renewed alone, and nobody else was evaluated after the first step
    // (nor at the restart: the held state continued).
    const auto &held = held_coulomb(a);
    std::printf("%d thread(s): %ld renewals of %.3g particles each, %ld whole evaluations in 80 steps\n", threads,
                held.renewals(), static_cast<double>(held.renewed()) / std::max(1L, held.renewals()),
                held.evaluations());
    EXPECT_GE(held.renewals(), 10);
    EXPECT_EQ(held.evaluations(), 1);
    EXPECT_EQ(held_coulomb(b).evaluations(), 1);
    x[threads - 1] = pa.x;
  }
  omp_set_num_threads(2);
  EXPECT_EQ(std::memcmp(x[0].data(), x[1].data(), x[0].size() * sizeof(double)), 0);
}
