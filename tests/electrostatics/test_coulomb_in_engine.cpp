// The Coulomb term inside the engine: the registry switches it on for a charged population
// (and the conductor images off in a box scene without sleeve or drum), and a run with a held
// far field restarts from a DemSystem checkpoint bit for bit.
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"

#include "coupling/case_parser.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cstring>
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
  fill(b);
  dem::add_case_force_terms(b, c);
  b.initialize();
  b.read_checkpoint(path);
  b.advance(20);
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
