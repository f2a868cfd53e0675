// The release measurement (dem/measurements/developer_release.h) against hand-made scenes: a
// ring of beads riding on the sleeve, of which every other one leaves the sleeve inside the
// release sector (released fraction 1/2 exactly, the arriving flux the ring's areal mass), and
// the scenes it is taken in (a release sector, with or without a doctor blade).
#include "dem/measurements/developer_release.h"
#include "sleeve_ring.h"

#include "case/case_parser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

constexpr double deg = M_PI / 180.0;
constexpr double R = 10e-3, Lz = 0.2e-3;

// The sector of a roller around its release, no blade; `dma` sets the measurement's keys.
Case release_case(const std::string &dma)
{
  const std::string text = R"(
name: release_test
scene: roller
roller:
  shaft_radius: 3 mm
  magnet_radius: 9.3 mm
  poles:
    - {name: S2, angle: 144 deg, strength: 200 kA/m, polarity: S}
    - {name: S3, angle: 216 deg, strength: 170 kA/m, polarity: S}
sleeve: {diameter: 20 mm, thickness: 0.5 mm, rpm: 400 rpm}
materials:
  carrier: {youngs_modulus: 1e3 MPa, density: 2200 kg/m^3, mu_r: 3.9}
  sleeve: {youngs_modulus: 5e4 MPa}
populations:
  - {name: carrier, kind: carrier, diameter: 50 um, count: 10, insert_box: [[-11 mm, -1 mm, 0 mm], [-9 mm, 1 mm, 0.2 mm]]}
dem: {periodic_length: 0.2 mm, duration: 1 ms}
)" + dma;
  return parse_case_text(text, "release_test.yaml");
}

std::map<std::string, SummaryValue> by_key(const std::vector<SummaryValue> &values)
{
  std::map<std::string, SummaryValue> out;
  for (const auto &v : values)
    out[v.key] = v;
  return out;
}

} // namespace

TEST(DeveloperRelease, EveryOtherBeadLeavingTheSleeveIsHalfReleased)
{
  // Release lines at 150 and 200 deg; past 175 deg the odd beads are 5 mm off the sleeve, beyond
  // dma.height: they no longer cross the second line.
  const Case c = release_case("dma: {release_from: 150 deg, release_to: 200 deg, height: 1 mm}\n");
  DeveloperRelease release(c);
  const int n = 360;
  const double m = 1e-10, spacing = 2 * M_PI / n, omega = c.sleeve->omega(), dt = spacing / 4.0 / omega;
  for (int k = 0; k <= 4 * 40; ++k)
  {
    ParticleState s = test_scenes::sleeve_ring(R, n, 0.2e-3, omega * k * dt, m);
    for (std::size_t i = 1; i < s.size(); i += 2)
    {
      const double a = std::fmod(std::atan2(s.y[i], s.x[i]) + 2 * M_PI, 2 * M_PI);
      if (a > 175 * deg && a < 300 * deg)
      {
        const double scale = (R + 5e-3) / std::hypot(s.x[i], s.y[i]);
        s.x[i] *= scale, s.y[i] *= scale;
      }
    }
    release.add_sample(k * dt, s);
  }
  const auto v = by_key(release.summary());
  EXPECT_NEAR(v.at("released_fraction").value, 0.5, 1e-9);
  // The ring carries n m over the sleeve's area 2π R Lz at the sleeve's speed: over whole
  // spacings (4 samples each) the arriving flux is that areal mass, and half of it goes on.
  const double areal = n * m / (2 * M_PI * R * Lz);
  EXPECT_NEAR(v.at("developer_arriving_at_release_kg_per_m2").value / areal, 1.0, 1e-9);
  EXPECT_NEAR(v.at("developer_carried_past_release_kg_per_m2").value / areal, 0.5, 1e-9);
  EXPECT_NEAR(v.at("developer_arriving_at_release_kg_per_m2").drift, 0.0, 1e-9);
}

TEST(DeveloperRelease, NothingReleasedWhenTheLayerStaysOnTheSleeve)
{
  const Case c = release_case("dma: {release_from: 150 deg, release_to: 200 deg, height: 1 mm}\n");
  DeveloperRelease release(c);
  const int n = 360;
  const double omega = c.sleeve->omega(), dt = 2 * M_PI / n / 4.0 / omega;
  for (int k = 0; k <= 4 * 40; ++k)
    release.add_sample(k * dt, test_scenes::sleeve_ring(R, n, 0.2e-3, omega * k * dt, 1e-10));
  EXPECT_NEAR(by_key(release.summary()).at("released_fraction").value, 0.0, 1e-12);
}

TEST(DeveloperRelease, TakenWhereverAReleaseSectorIsGivenWithOrWithoutABlade)
{
  EXPECT_TRUE(DeveloperRelease::applies(release_case("dma: {release_from: 150 deg, release_to: 200 deg}\n")));
  EXPECT_FALSE(DeveloperRelease::applies(release_case(""))); // no sector: nothing to measure
  Case no_slab = release_case("dma: {release_from: 150 deg, release_to: 200 deg}\n");
  no_slab.dem.periodic_length = 0.0;
  EXPECT_FALSE(DeveloperRelease::applies(no_slab));
  EXPECT_THROW(DeveloperRelease{no_slab}, std::invalid_argument);
}
