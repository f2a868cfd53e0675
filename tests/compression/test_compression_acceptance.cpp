// Kawamoto's compression test on a reduced scene: the acceptance of issue 5 (Kawamoto et al.,
// "fundamental investigation", Fig. 5, 6, 10, 12), asserted on the case file as users run it,
// shrunk to squares of ~12 bead diameters (0.7 mm for 60 um, 0.5 mm for 42 um: the same
// finite-size effects for both sizes) with the paper's magnetic cutoff (4 d + the slab tail)
// and a faster plate (protocol in compression_run.h). The full scene is the benchmark's.
//
//  * the normal force rises with compression and with B, as B² at low field (fitted exponent);
//  * sliding plate: tangential/normal = 0.35 ± 0.05 (the plate friction coefficient);
//  * beads touching the plate ∝ 1/d² and mean force per touching bead ∝ d², within ±20 %;
//  * the pressure at equal brush length and field nearly independent of d (within ±15 % of
//    the mean of the two sizes).
//
// Cost: two DEM runs on one thread, 62 s wall on the shared 2-core machine (load ~7).
#include "compression_run.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

using namespace magbrush;
using namespace magbrush::compression_test;
namespace fs = std::filesystem;

namespace {

struct Runs
{
  RunResult big;   // 60 um, 0.7 mm, with the field sweep and the slide
  RunResult small; // 42 um, 0.5 mm, compression and hold
};

class CompressionAcceptance : public ::testing::Test
{
protected:
  static Runs *runs;

  static void SetUpTestSuite()
  {
    runs = new Runs;
    const fs::path dir = fs::temp_directory_path() / ("magbrush_compression_" + std::to_string(::getpid()));
    ReducedScene s60;
    s60.diameter_um = 60;
    s60.box_mm = 0.7;
    // One thread: the same bits on any machine, and no spinning OpenMP team on a shared one.
    runs->big = run_case(reduced_case(s60, dir.string()), (dir / "60").string(), 1);
    ReducedScene s42 = s60;
    s42.diameter_um = 42;
    s42.box_mm = 0.5;
    s42.sweep_and_slide = false;
    runs->small = run_case(reduced_case(s42, dir.string()), (dir / "42").string(), 1);
    std::printf("reduced compression runs: 60 um %ld beads %.1f s wall (magnetics %.0f %%), "
                "42 um %ld beads %.1f s wall (magnetics %.0f %%)\n",
                runs->big.beads, runs->big.wall_s, 100 * runs->big.magnetic_s / runs->big.wall_s, runs->small.beads,
                runs->small.wall_s, 100 * runs->small.magnetic_s / runs->small.wall_s);
    fs::remove_all(dir);
  }
  static void TearDownTestSuite()
  {
    delete runs;
    runs = nullptr;
  }
};
Runs *CompressionAcceptance::runs = nullptr;

} // namespace

TEST_F(CompressionAcceptance, NormalForceRisesWithCompression)
{
  for (const RunResult *r : {&runs->big, &runs->small})
  {
    const WindowMean top = mean_at_length(r->rows, 0.90e-3, 1.0e-3);
    const WindowMean mid = mean_at_length(r->rows, 0.75e-3, 0.85e-3);
    const WindowMean low = mean_at_length(r->rows, 0.60e-3, 0.70e-3);
    std::printf("%ld beads: F_n = %.3f / %.3f / %.3f mN at 0.95 / 0.8 / 0.65 mm; touching %.1f / %.1f / %.1f\n",
                r->beads, top.fn * 1e3, mid.fn * 1e3, low.fn * 1e3, top.touching, mid.touching, low.touching);
    ASSERT_GT(top.rows, 0);
    ASSERT_GT(low.rows, 0);
    EXPECT_GT(low.fn, 1.3 * top.fn);
    EXPECT_GT(low.touching, top.touching);
  }
}

TEST_F(CompressionAcceptance, NormalForceGrowsAsBSquared)
{
  std::vector<double> b, f, b_low, f_low;
  for (const auto &h : field_holds())
  {
    const WindowMean m = mean_over(runs->big.rows, h.w);
    ASSERT_GT(m.rows, 0) << h.field_mT << " mT";
    EXPECT_NEAR(m.field * 1e3, h.field_mT, 1e-9); // the schedule is held
    std::printf("B = %5.1f mT: F_n = %.4f mN, %.1f beads touching\n", m.field * 1e3, m.fn * 1e3, m.touching);
    b.push_back(m.field);
    f.push_back(m.fn);
    if (h.field_mT <= 50)
    {
      b_low.push_back(m.field);
      f_low.push_back(m.fn);
    }
  }
  for (std::size_t i = 1; i < f.size(); ++i)
    EXPECT_LT(f[i], f[i - 1]) << "the force must fall with the field";
  const double k_low = power_law_exponent(b_low, f_low), k_all = power_law_exponent(b, f);
  std::printf("F ~ B^k: k = %.3f at 20-50 mT, %.3f over 20-130 mT\n", k_low, k_all);
  EXPECT_NEAR(k_low, 2.0, 0.25);
  EXPECT_NEAR(k_all, 2.0, 0.35);
}

TEST_F(CompressionAcceptance, TangentialOverNormalIsThePlateFriction)
{
  const WindowMean m = mean_over(runs->big.rows, slide_steady);
  ASSERT_GT(m.rows, 0);
  std::printf("sliding at %.3f mm: F_n = %.4f mN, F_t = %.4f mN, F_t/F_n = %.3f\n", m.gap * 1e3, m.fn * 1e3,
              m.ft * 1e3, m.ft / m.fn);
  EXPECT_NEAR(m.ft / m.fn, 0.35, 0.05);
}

TEST_F(CompressionAcceptance, TouchingDensityAndForcePerBeadScaleWithDiameter)
{
  const WindowMean a = mean_over(runs->big.rows, hold_130), b = mean_over(runs->small.rows, hold_130);
  ASSERT_GT(a.rows, 0);
  ASSERT_GT(b.rows, 0);
  const double density60 = a.touching / runs->big.area, density42 = b.touching / runs->small.area;
  const double per_bead60 = a.fn / a.touching, per_bead42 = b.fn / b.touching;
  const double d2 = (60.0 / 42.0) * (60.0 / 42.0);
  std::printf("at 0.6 mm, 130 mT: density %.1f / %.1f per mm² (60 / 42 um), ratio %.3f (d² ratio %.3f); "
              "force per bead %.2f / %.2f uN, ratio %.3f; spacing l/sqrt(n) %.1f / %.1f um\n",
              density60 * 1e-6, density42 * 1e-6, density42 / density60, d2, per_bead60 * 1e6, per_bead42 * 1e6,
              per_bead60 / per_bead42, 1e6 / std::sqrt(density60), 1e6 / std::sqrt(density42));
  EXPECT_NEAR(density42 / density60 / d2, 1.0, 0.20);
  EXPECT_NEAR(per_bead60 / per_bead42 / d2, 1.0, 0.20);
}

TEST_F(CompressionAcceptance, PressureNearlyIndependentOfDiameter)
{
  const WindowMean a = mean_over(runs->big.rows, hold_130), b = mean_over(runs->small.rows, hold_130);
  const double p60 = a.fn / runs->big.area, p42 = b.fn / runs->small.area, mean = 0.5 * (p60 + p42);
  std::printf("pressure at 0.6 mm, 130 mT: %.3f kPa (60 um), %.3f kPa (42 um)\n", p60 * 1e-3, p42 * 1e-3);
  EXPECT_NEAR(p60 / mean, 1.0, 0.15);
  EXPECT_NEAR(p42 / mean, 1.0, 0.15);
}
