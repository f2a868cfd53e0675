// The nip's asymmetry numbers (dem/measurements/nip_asymmetry.h) against profiles whose
// centroid, spread and up/down ratio are known by hand, and its block standard error against
// blocks whose centroids are known.
#include "dem/measurements/nip_asymmetry.h"

#include "common/state_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

std::map<std::string, SummaryValue> by_key(const std::vector<SummaryValue> &values)
{
  std::map<std::string, SummaryValue> out;
  for (const auto &v : values)
    out[v.key] = v;
  return out;
}

// Two beads: F1 at x1 < 0, F2 at x2 > 0 (and a third exactly at the centre, counted in the
// centroid but on neither side), shifted by `shift` along the nip.
void two_beads(NipAsymmetry &a, double shift)
{
  a.start_sample();
  a.add_contact(-0.3e-3 + shift, 2.0e-6);
  a.add_contact(0.5e-3 + shift, 1.0e-6);
  if (shift == 0.0)
    a.add_contact(0.0, 0.5e-6);
  a.end_sample();
}

} // namespace

TEST(NipAsymmetry, CentroidSpreadAndRatiosOfAKnownProfile)
{
  NipAsymmetry a;
  for (int n = 0; n < 40; ++n)
    two_beads(a, 0.0);
  const auto s = by_key(a.summary(10));
  // Forces 2, 1, 0.5 µN at −0.3, 0.5, 0 mm.
  const double F = 3.5e-6, Fx = 2e-6 * -0.3e-3 + 1e-6 * 0.5e-3, Fxx = 2e-6 * 0.09e-6 + 1e-6 * 0.25e-6;
  const double c = Fx / F;
  EXPECT_NEAR(s.at("pressure_centroid_m").value, c, 1e-18);
  EXPECT_NEAR(s.at("pressure_spread_m").value, std::sqrt(Fxx / F - c * c), 1e-15);
  EXPECT_DOUBLE_EQ(s.at("pressure_upstream_over_downstream").value, 2.0);
  EXPECT_NEAR(s.at("touching_centroid_m").value, 0.2e-3 / 3.0, 1e-18);
  EXPECT_NEAR(s.at("touching_spread_m").value,
              std::sqrt((0.09e-6 + 0.25e-6) / 3.0 - (0.2e-3 / 3.0) * (0.2e-3 / 3.0)), 1e-15);
  EXPECT_DOUBLE_EQ(s.at("touching_upstream_over_downstream").value, 1.0);
  // Every sample alike: no scatter between blocks.
  EXPECT_NEAR(s.at("pressure_centroid_m").standard_error, 0.0, 1e-18);
  EXPECT_NEAR(s.at("pressure_upstream_over_downstream").standard_error, 0.0, 1e-12);
}

// Four blocks of ten samples, the profile shifted rigidly by a different amount in each: the
// centroid moves with the shift and the spread does not; the centroid's standard error is that
// of the four shifts (the blocks weigh alike: the same forces in each); ten samples left over at
// the start are not in a block.
TEST(NipAsymmetry, TheBlockErrorIsTheScatterOfTheBlocksCentroids)
{
  NipAsymmetry a;
  for (int n = 0; n < 3; ++n)
    two_beads(a, 5e-3); // older than the blocks: left out of them, but in the window's sums
  const double shifts[] = {0.10e-3, -0.05e-3, 0.02e-3, 0.07e-3};
  for (double shift : shifts)
    for (int n = 0; n < 10; ++n)
      two_beads(a, shift);
  const auto s = by_key(a.summary(4));
  const double c0 = (2e-6 * -0.3e-3 + 1e-6 * 0.5e-3) / 3e-6;
  double mean = 0.0;
  for (double d : shifts)
    mean += d / 4.0;
  double ss = 0.0;
  for (double d : shifts)
    ss += (d - mean) * (d - mean);
  EXPECT_NEAR(s.at("pressure_centroid_m").standard_error, std::sqrt(ss / 3.0 / 4.0), 1e-15);
  EXPECT_NEAR(s.at("pressure_spread_m").standard_error, 0.0, 1e-15);
  // The value is that of the whole window, the 3 older samples included.
  const double window = (3 * 5e-3 + 10 * (0.10e-3 - 0.05e-3 + 0.02e-3 + 0.07e-3)) / 43.0;
  EXPECT_NEAR(s.at("pressure_centroid_m").value, c0 + window, 1e-15);

  // The state continues to the same summary.
  MemoryStateOut out;
  a.write_state(out);
  NipAsymmetry b;
  MemoryStateIn in(out.bytes(), "test state");
  b.read_state(in);
  EXPECT_EQ(in.remaining(), 0u);
  EXPECT_EQ(b.summary(4).front().value, s.at("pressure_centroid_m").value);
}
