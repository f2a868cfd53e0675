// The developed line (dem/measurements/developed_line.h) against layers whose developed mass is
// known by construction: toner on a lattice of drum-frame positions (k + ½) µm, a given mass on
// the exposed strips and another on the dark ones. The strips' edges (at ±0.5 mm + n · 2 mm) fall
// between lattice points, so any half-open stretch of one period holds exactly 1,000 exposed
// and 1,000 dark toner: each whole period's TMA and fog are exact whatever phase it starts at.
// The line sweeps the lattice in uneven steps, with toner already counted still on the drum
// (sliding back over the line once), toner landing past the line, a restart from the state, and
// samples before the averaging window.
#include "dem/measurements/developed_line.h"

#include "dem/measurements/sample_series.h"

#include "common/state_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

constexpr double period = 2e-3, depth = 0.1e-3, spacing = 1e-6;
constexpr double m_image = 3e-13, m_dark = 2e-14, q_per_mass = -0.03;

DrumImage image_of_period()
{
  LatentImage image;
  image.period = period;
  image.duty = 0.5;
  NipFrame frame; // the image's arcs are given directly here: the frame only places drum_arc
  return DrumImage(image, frame);
}

// The layer's toner k at drum arc (k + ½) spacing, its mass by the strip it lies on.
LineToner toner(const DrumImage &image, long k)
{
  const double s = (static_cast<double>(k) + 0.5) * spacing;
  const double m = image.exposed(s) ? m_image : m_dark;
  return {static_cast<std::int32_t>(k + 1000000), s, m, q_per_mass * m};
}

// The layer's toner on the drum around the line at s_line (70 µm either side: some counted
// already, some not yet across), sorted by id.
std::vector<LineToner> around(const DrumImage &image, double s_line)
{
  std::vector<LineToner> out;
  const long first = static_cast<long>(std::floor((s_line - 70e-6) / spacing));
  for (long k = first; k <= first + 140; ++k)
    out.push_back(toner(image, k));
  return out;
}

// Sweep the line from s0 downwards (the drum carries larger s past it first) over `length`,
// in uneven steps that do not divide a period, sampling at unit speed (time = distance swept).
void sweep(DevelopedLine &line, const DrumImage &image, double s0, double from, double to, bool counting = true)
{
  const double steps[] = {5.3e-6, 2.9e-6, 7.7e-6, 4.37e-6};
  int k = 0;
  for (double d = from; d < to; d += steps[k++ % 4])
    line.add_sample(d, s0 - d, around(image, s0 - d), counting);
}

} // namespace

TEST(DevelopedLine, EveryWholePeriodHasTheLayersExactTmaAndFogWhateverItsPhase)
{
  const DrumImage image = image_of_period();
  for (double s0 : {0.0, 0.3337e-3, -1.1e-3, 7.77e-3})
  {
    DevelopedLine line(image, depth, 40);
    sweep(line, image, s0, 0.0, 3.5 * period);
    ASSERT_EQ(line.periods().size(), 3u) << s0;
    EXPECT_NEAR(line.open_period_length(), 0.5 * period, 8e-6) << s0; // the last step overshoots
    for (const auto &p : line.periods())
    {
      EXPECT_EQ(p.image_toner, 1000) << s0;
      EXPECT_EQ(p.dark_toner, 1000) << s0;
      EXPECT_NEAR(p.image_area, 1e-3 * depth, 1e-15);
      EXPECT_NEAR(p.dark_area, 1e-3 * depth, 1e-15);
      EXPECT_NEAR(p.image_mass / p.image_area, m_image / (spacing * depth), 1e-9 * m_image / (spacing * depth));
      EXPECT_NEAR(p.dark_mass / p.dark_area, m_dark / (spacing * depth), 1e-9 * m_dark / (spacing * depth));
      EXPECT_NEAR(p.image_charge / p.image_mass, q_per_mass, 1e-12);
      EXPECT_NEAR(p.t_end - p.t_start, period, 1e-12); // unit speed: a period's span is its length
    }
    // The profile: 50 µm bins, 50 toner each per period; exposed within ±0.5 mm of the strip's centre.
    for (int k = 0; k < 40; ++k)
    {
      const auto &b = line.profile()[static_cast<std::size_t>(k)];
      const bool exposed = std::abs(line.bin_position(k)) < 0.5e-3;
      EXPECT_EQ(b.toner, 150) << k;
      EXPECT_NEAR(b.length, 3 * 50e-6, 1e-15) << k;
      EXPECT_NEAR(b.mass / (b.length * depth), (exposed ? m_image : m_dark) / (spacing * depth), 1e-9 * m_image / (spacing * depth)) << k;
    }
  }
}

// A solid area (duty 1) and a dark drum have no period: the blocks are the block length, every
// block holds exactly its 700 lattice toner (0.7 mm blocks against 1 µm spacing, the block
// boundaries between lattice points), all image on the solid area, all background on the dark
// drum; the profile is flat. The blocks lie on a grid fixed to the drum, wherever the counting
// starts: the stretch up to the first boundary is swept but not kept.
TEST(DevelopedLine, AUniformImageIsAveragedOverBlocksOfTheGivenLength)
{
  constexpr double block = 0.7e-3;
  for (double duty : {1.0, 0.0})
  {
    LatentImage uniform;
    uniform.period = duty >= 1.0 ? period : 0.0; // a solid area whatever the period
    uniform.duty = duty;
    const DrumImage image(uniform, NipFrame{});
    EXPECT_EQ(image.period(), 0.0);
    EXPECT_EQ(image.exposed(0.3e-3), duty >= 1.0);
    EXPECT_NEAR(image.exposed_length(-1e-3, 2e-3), duty >= 1.0 ? 3e-3 : 0.0, 1e-18);
    EXPECT_THROW(DevelopedLine(image, depth, 7), std::invalid_argument); // no period, no block length
    for (double s0 : {0.0, 0.3337e-3, -1.1e-3})
    {
      DevelopedLine line(image, depth, 7, block);
      EXPECT_EQ(line.block_length(), block);
      sweep(line, image, s0, 0.0, 3.5 * block);
      ASSERT_EQ(line.periods().size(), 3u) << s0;
      for (const auto &p : line.periods())
      {
        const double m = duty >= 1.0 ? m_image : m_dark;
        EXPECT_EQ(p.image_toner + p.dark_toner, 700) << s0;
        EXPECT_EQ(duty >= 1.0 ? p.dark_toner : p.image_toner, 0) << s0;
        EXPECT_NEAR(duty >= 1.0 ? p.image_area : p.dark_area, block * depth, 1e-15);
        EXPECT_NEAR((duty >= 1.0 ? p.image_mass / p.image_area : p.dark_mass / p.dark_area), m / (spacing * depth),
                    1e-9 * m / (spacing * depth));
        EXPECT_NEAR(p.t_end - p.t_start, block, 1e-12);
      }
      // The blocks lie on the drum's grid of 0.7 mm (the stretch before the first boundary is
      // not kept): their indices say which drum elements they hold.
      const long first = static_cast<long>(std::floor(s0 / block + 1e-9));
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_EQ(line.grid_index(line.periods()[k]), first - static_cast<long>(k)) << s0;
      for (int k = 0; k < 7; ++k)
      {
        const auto &b = line.profile()[static_cast<std::size_t>(k)];
        EXPECT_EQ(b.toner, 300) << k; // 100 µm bins, three blocks
        EXPECT_NEAR(line.bin_position(k), (k + 0.5) * 100e-6, 1e-15);
      }
    }
  }
}

TEST(DevelopedLine, TonerIsCountedOnceAndOnlyAsItsElementCrosses)
{
  const DrumImage image = image_of_period();
  DevelopedLine line(image, depth, 40);
  // Before the averaging window nothing counts; the first counted interval starts at the
  // first sample in it.
  sweep(line, image, 0.0, 0.0, 0.5e-3, false);
  EXPECT_TRUE(line.periods().empty());
  EXPECT_EQ(line.open_period_length(), 0.0);
  // Then a period and a bit, where one toner already counted slides back over the line, and a
  // toner lands far past it (it never crosses: not counted).
  const double steps = 5e-6;
  double d = 0.5e-3;
  bool slid = false;
  for (; d < 0.5e-3 + period + 0.1e-3; d += steps)
  {
    std::vector<LineToner> on = around(image, -d);
    if (!slid && d > 1e-3)
    {
      // A toner counted at the previous sample (its arc in −d + steps .. −d + 2 steps) slides
      // back into the interval this sample counts.
      for (auto &t : on)
        if (t.s > -d + steps && t.s < -d + 1.5 * steps)
        {
          t.s = -d + 0.5 * steps;
          slid = true;
          break;
        }
    }
    on.push_back({99, -d + 40e-6, 5e-12, 0.0}); // landed past the line (id 99 first: sorted)
    std::sort(on.begin(), on.end(), [](const LineToner &a, const LineToner &b) { return a.id < b.id; });
    line.add_sample(d, -d, on, true);
  }
  ASSERT_TRUE(slid);
  ASSERT_EQ(line.periods().size(), 1u);
  EXPECT_EQ(line.periods()[0].image_toner, 1000);
  EXPECT_EQ(line.periods()[0].dark_toner, 1000);
}

TEST(DevelopedLine, ARestartFromItsStateContinuesBitForBit)
{
  const DrumImage image = image_of_period();
  DevelopedLine whole(image, depth, 40), first(image, depth, 40);
  sweep(whole, image, 0.2e-3, 0.0, 2.5 * period);
  sweep(first, image, 0.2e-3, 0.0, 1.3 * period);
  MemoryStateOut out;
  first.write_state(out);
  DevelopedLine second(image, depth, 40);
  MemoryStateIn in(out.bytes(), "test state");
  second.read_state(in);
  EXPECT_EQ(in.remaining(), 0u);
  // The same uneven steps, continued where the first part stopped.
  const double steps[] = {5.3e-6, 2.9e-6, 7.7e-6, 4.37e-6};
  int k = 0;
  double d = 0.0;
  for (; d < 1.3 * period; d += steps[k++ % 4])
    ;
  for (; d < 2.5 * period; d += steps[k++ % 4])
    second.add_sample(d, 0.2e-3 - d, around(image, 0.2e-3 - d), true);
  EXPECT_EQ(second.periods_csv(), whole.periods_csv());
  EXPECT_EQ(second.profile_csv(), whole.profile_csv());
  // A profile of another bin count does not read it.
  DevelopedLine other(image, depth, 20);
  MemoryStateIn again(out.bytes(), "test state");
  EXPECT_ANY_THROW(other.read_state(again));
}

TEST(SummariseBlocks, MeanErrorAndDriftOfIndependentBlocks)
{
  const SummaryValue v = summarise_blocks({1.0, 2.0, 3.0, 4.0}, true, "x", "1", "");
  EXPECT_DOUBLE_EQ(v.value, 2.5);
  EXPECT_NEAR(v.standard_error, std::sqrt(5.0 / 3.0 / 4.0), 1e-12); // sample variance 5/3, four blocks
  EXPECT_NEAR(v.drift, (3.5 - 1.5) / 2.5, 1e-12);
  EXPECT_NEAR(v.drift_standard_error, std::sqrt(0.25 + 0.25) / 2.5, 1e-12);
  // Two blocks: a drift, no error of it; one block: neither an error nor a drift.
  const SummaryValue two = summarise_blocks({2.0, 2.1}, true, "x", "1", "");
  EXPECT_NEAR(two.drift, 0.1 / 2.05, 1e-12);
  EXPECT_TRUE(std::isnan(two.drift_standard_error));
  const SummaryValue one = summarise_blocks({2.0}, true, "x", "1", "");
  EXPECT_DOUBLE_EQ(one.value, 2.0);
  EXPECT_TRUE(std::isnan(one.standard_error));
  EXPECT_TRUE(std::isnan(one.drift));
  // Not tested for steady state: no drift.
  EXPECT_TRUE(std::isnan(summarise_blocks({1.0, 2.0, 3.0, 4.0}, false, "x", "1", "").drift));
}
