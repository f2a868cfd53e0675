// The DMA measurement against values computed here from hand-made scenes: a ring of beads
// riding on the sleeve (areal DMA from the count in the window; the flux form equals it over
// whole spacings of the ring), the height filter, the developer held in front of the blade,
// the blade's load resolved at its tip and the bound from the generated blade's gap.
#include "dem/measurements/developer_mass_per_area.h"
#include "sleeve_ring.h"

#include "case/case_parser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

constexpr double deg = M_PI / 180.0;
constexpr double R = 10e-3, Lz = 0.2e-3;

// A roller scene with a generated doctor blade at 270 deg, gap 0.5 mm, sleeve turning
// counter-clockwise at 400 rpm (or `rpm`); `extra` adds keys (dma.*).
Case blade_case(const std::string &extra = "", const std::string &rpm = "400 rpm")
{
  const std::string text = R"(
name: dma_test
scene: roller
roller:
  shaft_radius: 3 mm
  magnet_radius: 9.3 mm
  poles:
    - {name: N1, angle: 0 deg, strength: 100 kA/m, polarity: N}
sleeve: {diameter: 20 mm, thickness: 0.5 mm, rpm: )" + rpm + R"(}
blades:
  - {name: doctor, kind: doctor_blade, angle: 270 deg, gap: 0.5 mm, thickness: 1.5 mm, length: 8 mm}
materials:
  carrier: {youngs_modulus: 1e3 MPa, density: 2200 kg/m^3, mu_r: 3.9}
  sleeve: {youngs_modulus: 5e4 MPa}
  wall: {youngs_modulus: 5e4 MPa}
populations:
  - {name: carrier, kind: carrier, diameter: 50 um, count: 10, insert_box: [[9 mm, -1 mm, 0 mm], [11 mm, 1 mm, 0.2 mm]]}
dem: {periodic_length: 0.2 mm, duration: 1 ms}
)" + extra;
  return parse_case_text(text, "dma_test.yaml");
}

ParticleState ring(int n, double h, double phi, double m_each)
{
  return test_scenes::sleeve_ring(R, n, h, phi, m_each);
}

} // namespace

TEST(DeveloperMassPerArea, BladeTipAndBoundFromTheGeneratedBlade)
{
  const Case c = blade_case();
  ASSERT_TRUE(DeveloperMassPerArea::applies(c));
  const DeveloperMassPerArea dma(c);
  EXPECT_NEAR(std::remainder(dma.blade_angle() - 270 * deg, 2 * M_PI), 0.0, 1e-9);
  EXPECT_NEAR(dma.dma_bound(), 0.64 * 2200.0 * 0.5e-3, 1e-9);
}

TEST(DeveloperMassPerArea, AreaAndFluxFormsOfARingRidingOnTheSleeve)
{
  const Case c = blade_case("dma: {after_blade: 10 deg, window: 12 deg, height: 1 mm, sample_interval: 10 us}\n");
  DeveloperMassPerArea dma(c);
  const int n = 360;                      // one bead per degree: 12 in the window, none on its edges
  const double m = 1e-10, spacing = 2 * M_PI / n;
  const double omega = c.sleeve->omega(); // the ring rides with the sleeve
  const double dt = spacing / 4.0 / omega;
  // Turned by an eighth of a spacing at the start, no bead ever sits on an edge or the line.
  for (int k = 0; k <= 4 * 25; ++k)     // 25 whole spacings after the first sample
    dma.add_sample(k * dt, ring(n, 0.2e-3, spacing / 8.0 + omega * k * dt, m), Vector3{});
  const double exact = m / (spacing * R * Lz); // the ring's mass per sleeve area
  const auto summary = dma.summary();
  auto value = [&](const std::string &key) {
    for (const auto &v : summary)
      if (v.key == key)
        return v.value;
    return std::nan("");
  };
  // The window holds 12 beads at every sample (turns of a quarter spacing keep the count).
  EXPECT_NEAR(value("dma_kg_per_m2"), exact, 1e-9 * exact);
  // One bead crosses the centre line per spacing turned: over whole spacings, exactly the areal form.
  EXPECT_NEAR(value("dma_flux_kg_per_m2"), exact, 1e-9 * exact);
  // Held in front: 20 deg before the tip hold 20 beads.
  EXPECT_NEAR(value("developer_held_in_front_of_blade_kg_per_m"), 20 * m / Lz, 1e-9 * 20 * m / Lz);
}

TEST(DeveloperMassPerArea, OnlyTheLayerOnTheSleeveCounts)
{
  const Case c = blade_case("dma: {height: 1 mm}\n");
  DeveloperMassPerArea low(c), high(c);
  low.add_sample(0.0, ring(360, 0.9e-3, 0.0, 1e-10), Vector3{});
  high.add_sample(0.0, ring(360, 1.1e-3, 0.0, 1e-10), Vector3{});
  EXPECT_GT(low.summary()[0].value, 0.0);
  EXPECT_EQ(high.summary()[0].value, 0.0);
}

TEST(DeveloperMassPerArea, BladeLoadAlongItsRadiusAndAlongTheSleevesMotion)
{
  const Case c = blade_case();
  DeveloperMassPerArea dma(c);
  // The tip is at 270 deg: the outward radius is −y, the sleeve (counter-clockwise) moves +x there.
  dma.add_sample(0.0, ParticleState{}, Vector3{2e-3, -3e-3, 0.0});
  const auto s = dma.summary();
  for (const auto &v : s)
  {
    if (v.key == "blade_force_N_per_m")
    {
      EXPECT_NEAR(v.value, 3e-3 / Lz, 1e-9);
    }
    if (v.key == "blade_drag_N_per_m")
    {
      EXPECT_NEAR(v.value, 2e-3 / Lz, 1e-9);
    }
  }
}

// A layer in the blade's gap turning at a fraction of the sleeve's angular speed, under a layer
// above the gap's height turning faster: the ratio is the fraction, whatever the sense of turning.
TEST(DeveloperMassPerArea, SpeedInTheGapAgainstTheSleeves)
{
  for (const char *rpm : {"400 rpm", "-400 rpm"})
  {
    const Case c = blade_case("", rpm);
    DeveloperMassPerArea dma(c);
    const double omega = c.sleeve->omega();
    ParticleState s = ring(360, 0.2e-3, 0.0, 1e-10); // in the gap (0.5 mm)
    const std::size_t in_gap = s.size();
    const ParticleState above = ring(360, 0.7e-3, 0.0, 1e-10);
    for (std::size_t i = 0; i < above.size(); ++i)
      s.add(above.position(i), above.radius[i], above.mass[i] / (4.0 / 3.0 * M_PI * std::pow(above.radius[i], 3)), 0,
            0.0);
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      const double w = (i < in_gap ? 0.6 : 2.0) * omega; // rigid turning at w
      s.vx[i] = -w * s.y[i];
      s.vy[i] = w * s.x[i];
    }
    dma.add_sample(0.0, s, Vector3{});
    double ratio = std::nan("");
    for (const auto &v : dma.summary())
      if (v.key == "blade_gap_speed_ratio")
        ratio = v.value;
    EXPECT_NEAR(ratio, 0.6, 1e-12) << rpm;
  }
}

TEST(DeveloperMassPerArea, RegisteredOnlyForASceneWithADoctorBlade)
{
  Case c = blade_case();
  EXPECT_TRUE(DeveloperMassPerArea::applies(c));
  c.blades.clear();
  EXPECT_FALSE(DeveloperMassPerArea::applies(c));
}
