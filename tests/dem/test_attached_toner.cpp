// Toner attached to the carriers (populations[].attached, dem/insertion.cpp): developer as it
// is carried, every toner touching a carrier's surface and nothing overlapping, each carrier
// carrying about the concentration times its own mass, the whole toner mass the concentration
// times the carriers'. The same toner placed at random in a box (the default) mostly touches
// nothing, so the touching test can fail.
#include "dem/dem_system.h"

#include "case/case_parser.h"

#include "tests/case_error.h"
#include "tests/dem/box_developer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace magbrush;

namespace {
dem::ParticleState inserted(const std::string &yaml)
{
  const Case c = parse_case_text(yaml, "developer.yaml");
  dem::DemSystem system(c);
  system.insert_particles();
  return system.particles();
}

// Surface gap between particles a and b, periodic along x and y (1 mm).
double gap(const dem::ParticleState &s, std::size_t a, std::size_t b)
{
  double dx = s.x[a] - s.x[b], dy = s.y[a] - s.y[b];
  dx -= 1e-3 * std::round(dx / 1e-3);
  dy -= 1e-3 * std::round(dy / 1e-3);
  const double dz = s.z[a] - s.z[b];
  return std::sqrt(dx * dx + dy * dy + dz * dz) - s.radius[a] - s.radius[b];
}

struct Layout
{
  std::size_t toner = 0, touching = 0, carriers = 0, carriers_with_toner = 0;
  double min_gap = std::numeric_limits<double>::max();
  double toner_mass = 0.0, carrier_mass = 0.0;
  std::vector<double> carried; // per carrier: toner mass touching it / its own mass
};

Layout layout_of(const dem::ParticleState &s)
{
  Layout out;
  std::vector<std::size_t> carriers;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.species[k] == 0)
    {
      carriers.push_back(k);
      out.carrier_mass += s.mass[k];
    }
  out.carriers = carriers.size();
  std::vector<double> carried(s.size(), 0.0);
  for (std::size_t a = 0; a < s.size(); ++a)
  {
    for (std::size_t b = a + 1; b < s.size(); ++b)
      out.min_gap = std::min(out.min_gap, gap(s, a, b) / std::min(s.radius[a], s.radius[b]));
    if (s.species[a] != 1)
      continue;
    ++out.toner;
    out.toner_mass += s.mass[a];
    for (std::size_t c : carriers)
      if (std::abs(gap(s, a, c)) < 1e-6 * s.radius[a])
      {
        ++out.touching;
        carried[c] += s.mass[a];
        break;
      }
  }
  for (std::size_t c : carriers)
  {
    out.carried.push_back(carried[c] / s.mass[c]);
    out.carriers_with_toner += carried[c] > 0.0;
  }
  return out;
}
} // namespace

TEST(AttachedToner, EveryTonerTouchesACarrierAndEachCarriesTheConcentration)
{
  const Layout l = layout_of(inserted(magbrush::testing::box_developer("attached: true")));
  ASSERT_GT(l.toner, 1000u); // 150 carriers × ~17 toner
  EXPECT_EQ(l.touching, l.toner);
  EXPECT_GT(l.min_gap, -1e-9) << "particles overlap";
  // The whole: the concentration times the carriers' mass, to within one toner (~2e-13 kg).
  EXPECT_NEAR(l.toner_mass, 0.05 * l.carrier_mass, 4e-13);
  // Each carrier: the running balance gives each its share to within a toner or two
  // (a 35 µm carrier's 5 % is ~17 toner of 7 µm); none is left bare.
  EXPECT_EQ(l.carriers_with_toner, l.carriers);
  double mean = 0.0;
  for (double f : l.carried)
    mean += f / static_cast<double>(l.carried.size());
  EXPECT_NEAR(mean, 0.05, 0.002);
  const auto [lo, hi] = std::minmax_element(l.carried.begin(), l.carried.end());
  EXPECT_GT(*lo, 0.03);
  EXPECT_LT(*hi, 0.07);
}

TEST(AttachedToner, TonerPlacedInTheBoxMostlyTouchesNothing)
{
  const Layout l =
      layout_of(inserted(magbrush::testing::box_developer("insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]]")));
  EXPECT_LT(l.touching, l.toner / 10);
}

TEST(AttachedToner, OnlyTonerGivenByAConcentrationIsAttachedAndItTakesNoRegion)
{
  auto error_of = [](const std::string &yaml) { return magbrush::testing::case_error_of(yaml, "developer.yaml"); };
  std::string by_count = magbrush::testing::box_developer("attached: true");
  by_count.replace(by_count.find("concentration: 5 %"), 18, "count: 100");
  const std::string count = error_of(by_count);
  EXPECT_NE(count.find("populations.toner.attached"), std::string::npos) << count;
  EXPECT_NE(count.find("concentration"), std::string::npos) << count;

  const std::string region = error_of(magbrush::testing::box_developer("attached: true, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]]"));
  EXPECT_NE(region.find("give no insert_box"), std::string::npos) << region;

  std::string carrier = magbrush::testing::box_developer("attached: true");
  carrier.replace(carrier.find("counter_charge: true"), 20, "attached: true");
  const std::string on_carrier = error_of(carrier);
  EXPECT_NE(on_carrier.find("populations.carrier.attached"), std::string::npos) << on_carrier;
}
