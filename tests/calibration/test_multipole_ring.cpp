// Verification of the exact multipole-ring solution (fields/multipole_ring.h):
//  * the classical μr = 1 ring, B_x − i B_y = μ0 n E_n z^−(n+1), to 1e-12;
//  * the interface conditions and the field equations themselves for μ ≠ 1 layers;
//  * the ideal-iron limit μ_s → ∞;
//  * the convergence of the Fourier series of the Gaussian pole model;
//  * the example gaussmeter scan (cases/data/sleeve_profile_example.csv), which was generated
//    from the same exact solution plus 0.4 mT noise: the residual must be that noise.
#include "fields/multipole_ring.h"
#include "tests/calibration/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>

using namespace magbrush;
using namespace magbrush::flux_test;

namespace {

// Ring R_i < r < R_o in air: the "shaft" is air (μ_s = 1), the magnet has μ_m = 1.
RingGeometry air_ring(double Ri, double Ro)
{
  RingGeometry g;
  g.shaft_radius = Ri;
  g.shaft_mu_r = 1.0;
  g.magnet_radius = Ro;
  g.magnet_mu_r = 1.0;
  return g;
}

} // namespace

TEST(MultipoleRing, ExteriorCoefficientMatchesClosedForm)
{
  const double Ri = 4e-3, Ro = 10e-3, rho = Ri / Ro;
  double worst = 0.0;
  for (int n = 1; n <= 80; ++n)
  {
    const MultipoleRing::HarmonicResponse h(air_ring(Ri, Ro), n);
    const double exact = (1.0 - std::pow(rho, n + 1)) / (2.0 * (n + 1));
    worst = std::max(worst, std::abs(h.exterior_coefficient() - exact) / exact);
  }
  std::printf("max relative error of E_n/(M R_o^(n+1)), n = 1..80: %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(MultipoleRing, ExteriorFieldMatchesComplexClosedForm)
{
  // M_r = M cos(n(θ − θ0)) as a cos + b sin: the rotated ring, B_x − i B_y = μ0 n E_n e^{inθ0} z^−(n+1).
  const double Ri = 3e-3, Ro = 9e-3, M = 2.5e5, theta0 = 0.3;
  double worst = 0.0;
  for (int n : {1, 2, 3, 5, 8, 13})
  {
    const MultipoleRing ring(air_ring(Ri, Ro),
                             {{n, M * std::cos(n * theta0), M * std::sin(n * theta0)}});
    const double En = M * std::pow(Ro, n + 1) * (1.0 - std::pow(Ri / Ro, n + 1)) / (2.0 * (n + 1));
    for (double r : {9.0e-3, 10e-3, 12.5e-3, 20e-3})
      for (double t : {0.0, 0.7, 2.0, -2.9})
      {
        const std::complex<double> z = std::polar(r, t);
        const std::complex<double> exact =
            mu0 * n * En * std::polar(1.0, n * theta0) * std::pow(z, -(n + 1));
        const RingField f = ring.field(z.real(), z.imag());
        const double scale = std::abs(exact);
        worst = std::max(worst, std::abs(std::complex<double>(f.Bx, -f.By) - exact) / scale);
      }
  }
  std::printf("max relative error of B_x − i B_y outside the ring: %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

// A general layered roller: B_r continuous, H_θ continuous, and inside each layer
// div B = 0, curl H = 0 and B = curl A (checked by central differences).
TEST(MultipoleRing, SatisfiesInterfaceConditionsAndFieldEquations)
{
  RingGeometry g;
  g.shaft_radius = 3e-3;
  g.shaft_mu_r = 250.0;
  g.magnet_radius = 9.3e-3;
  g.magnet_mu_r = 1.08;
  const MultipoleRing ring(g, {{1, 1e5, -3e4}, {2, 4e4, 2e4}, {3, -2e5, 1e5}, {7, 5e4, 6e4}});
  const double eps = 1e-13; // relative radial offset across an interface
  double worst_jump = 0.0;
  for (double t : {0.1, 1.3, 2.9, 4.4})
  {
    const RingField si = ring.field_polar(g.shaft_radius * (1 - eps), t);
    const RingField so = ring.field_polar(g.shaft_radius * (1 + eps), t);
    const RingField mi = ring.field_polar(g.magnet_radius * (1 - eps), t);
    const RingField mo = ring.field_polar(g.magnet_radius * (1 + eps), t);
    const double scale = std::abs(mo.Br) + std::abs(mo.Btheta);
    worst_jump = std::max({worst_jump, std::abs(si.Br - so.Br) / scale,
                           std::abs(si.Btheta / g.shaft_mu_r - so.Btheta / g.magnet_mu_r) / scale,
                           std::abs(mi.Br - mo.Br) / scale,
                           std::abs(mi.Btheta / g.magnet_mu_r - mo.Btheta) / scale,
                           std::abs(si.Az - so.Az) / (scale * g.shaft_radius),
                           std::abs(mi.Az - mo.Az) / (scale * g.magnet_radius)});
  }
  std::printf("largest interface mismatch (B_r, H_θ, A_z), relative: %.2e\n", worst_jump);
  EXPECT_LT(worst_jump, 1e-10);

  // Field equations by central differences (h = 1 µm) at points inside each layer.
  const double h = 1e-6;
  double worst_div = 0, worst_curl = 0, worst_curlA = 0;
  for (double r : {1.5e-3, 6e-3, 11e-3})
    for (double t : {0.4, 2.2, 5.0})
    {
      const double x = r * std::cos(t), y = r * std::sin(t);
      const RingField c = ring.field(x, y);
      const RingField xp = ring.field(x + h, y), xm = ring.field(x - h, y);
      const RingField yp = ring.field(x, y + h), ym = ring.field(x, y - h);
      const double scale = std::hypot(c.Bx, c.By) / r;
      const double mu = r < g.shaft_radius ? g.shaft_mu_r : (r < g.magnet_radius ? g.magnet_mu_r : 1.0);
      // div B = ∂Bx/∂x + ∂By/∂y = 0 everywhere (also in the magnet).
      worst_div = std::max(worst_div, std::abs((xp.Bx - xm.Bx + yp.By - ym.By) / (2 * h)) / scale);
      // curl H = 0 with H = (B/μ0 − M)/μ: M is radial, so curl M = (1/r) ∂M_r/∂θ ẑ ≠ 0 in the
      // magnet; only check outside the magnet and in the shaft, where M = 0.
      if (r < g.shaft_radius || r > g.magnet_radius)
        worst_curl = std::max(worst_curl,
                              std::abs((xp.By - xm.By - (yp.Bx - ym.Bx)) / (2 * h)) / (mu * scale));
      // B = curl A:  Bx = ∂A/∂y, By = −∂A/∂x
      worst_curlA = std::max({worst_curlA, std::abs((yp.Az - ym.Az) / (2 * h) - c.Bx) / (scale * r),
                              std::abs(-(xp.Az - xm.Az) / (2 * h) - c.By) / (scale * r)});
    }
  std::printf("central differences: |div B| %.1e, |curl H| %.1e, |B − curl A| %.1e (relative)\n",
              worst_div, worst_curl, worst_curlA);
  EXPECT_LT(worst_div, 1e-5);
  EXPECT_LT(worst_curl, 1e-5);
  EXPECT_LT(worst_curlA, 1e-5);
}

// Inside the magnet curl H = 0 means curl B = μ0 curl M (M radial, so curl M ≠ 0 there).
TEST(MultipoleRing, CurlOfHInTheMagnetEqualsCurlOfMagnetisation)
{
  RingGeometry g;
  g.shaft_radius = 2e-3;
  g.shaft_mu_r = RingGeometry::ideal_iron;
  g.magnet_radius = 9e-3;
  g.magnet_mu_r = 1.05;
  const int n = 4;
  const double M = 3e5;
  const MultipoleRing ring(g, {{n, M, 0.0}});
  // μ0 μ_m curl H = curl B − μ0 curl M; curl(M_r r̂)_z = −(1/r) ∂M_r/∂θ = (n M/r) sin nθ.
  const double r = 6e-3, t = 0.37, h = 1e-6;
  const double x = r * std::cos(t), y = r * std::sin(t);
  const RingField xp = ring.field(x + h, y), xm = ring.field(x - h, y);
  const RingField yp = ring.field(x, y + h), ym = ring.field(x, y - h);
  const double curlB = (xp.By - xm.By - (yp.Bx - ym.Bx)) / (2 * h);
  const double curlM = n * M / r * std::sin(n * t);
  EXPECT_NEAR(curlB, mu0 * curlM, 1e-6 * std::abs(mu0 * curlM));
}

TEST(MultipoleRing, IdealIronIsTheLimitOfLargeShaftPermeability)
{
  Roller roller = example_roller();
  const MultipoleRing ideal(roller);
  std::printf("  mu_s       max |B - B_ideal| / max |B|   on r = 10 mm\n");
  double previous = 1e300;
  for (double mu_s : {1e2, 1e4, 1e6, 1e8})
  {
    roller.shaft_mu_r = mu_s;
    const MultipoleRing finite(roller);
    double diff = 0, scale = 0;
    for (int k = 0; k < 72; ++k)
    {
      const double t = k * 5.0 * M_PI / 180.0;
      const RingField a = ideal.field_polar(10e-3, t), b = finite.field_polar(10e-3, t);
      diff = std::max({diff, std::abs(a.Br - b.Br), std::abs(a.Btheta - b.Btheta)});
      scale = std::max(scale, std::abs(a.Br));
    }
    std::printf("  %8.0e   %.3e\n", mu_s, diff / scale);
    EXPECT_LT(diff / scale, previous); // monotone approach
    EXPECT_LT(diff / scale, 2.0 / mu_s); // the error is O(1/μ_s)
    previous = diff / scale;
  }
  // On ideal iron the field is normal: B_θ = 0 on the magnet side of the shaft surface.
  for (double t : {0.0, 1.0, 2.5})
  {
    const RingField f = ideal.field_polar(3e-3 * (1 + 1e-14), t);
    EXPECT_LT(std::abs(f.Btheta), 1e-10 * std::abs(f.Br) + 1e-12);
  }
}

TEST(MultipoleRing, FourierSeriesOfThePoleModelConverges)
{
  const Roller roller = example_roller();
  const MultipoleRing reference(roller, {200, 1e-14, 1024});
  const MultipoleRing automatic(roller);
  std::printf("automatic harmonic count: %d (largest neglected coefficient %.1e of the largest)\n",
              automatic.harmonic_count(), automatic.harmonic_choice().tail);
  EXPECT_GE(automatic.harmonic_count(), 30);
  EXPECT_LE(automatic.harmonic_count(), 60);
  // Magnetisation M_r(θ) against the pole formula, and B on the magnet surface against the
  // 200-harmonic reference, as the number of harmonics grows.
  std::printf("   N    max|M_N − M|/max|M|    max|B_N − B_ref|/max|B| at r = R_m\n");
  double previous_m = 1e300;
  for (int N : {5, 10, 15, 20, 25, 30, 35})
  {
    const MultipoleRing ring(roller, {N, 1e-14, 1024});
    double em = 0, sm = 0, eb = 0, sb = 0;
    for (int k = 0; k < 720; ++k)
    {
      const double t = k * M_PI / 360.0;
      em = std::max(em, std::abs(ring.magnetisation(t) - pole_magnetisation(roller, t)));
      sm = std::max(sm, std::abs(pole_magnetisation(roller, t)));
      const RingField a = ring.field_polar(roller.magnet_radius, t);
      const RingField b = reference.field_polar(roller.magnet_radius, t);
      eb = std::max(eb, std::hypot(a.Br - b.Br, a.Btheta - b.Btheta));
      sb = std::max(sb, std::hypot(b.Br, b.Btheta));
    }
    std::printf("  %3d   %.2e               %.2e\n", N, em / sm, eb / sb);
    EXPECT_LT(em / sm, previous_m);
    previous_m = em / sm;
    if (N == 35)
    {
      EXPECT_LT(em / sm, 1e-12);
      EXPECT_LT(eb / sb, 1e-12);
    }
  }
}

TEST(MultipoleRing, ReproducesTheExampleScanToItsNoise)
{
  const auto scan = read_example_scan_plain();
  const MultipoleRing ring(example_roller());
  std::vector<double> Bn, Bt;
  ring.profile(10e-3, scan.angle, Bn, Bt);
  double sn = 0, st = 0, mn = 0, mt = 0;
  const double count = scan.angle.size();
  for (size_t k = 0; k < scan.angle.size(); ++k)
  {
    sn += std::pow(Bn[k] - scan.Bn[k], 2);
    st += std::pow(Bt[k] - scan.Bt[k], 2);
    mn += (scan.Bn[k] - Bn[k]) / count;
    mt += (scan.Bt[k] - Bt[k]) / count;
  }
  const double rms_n = std::sqrt(sn / count), rms_t = std::sqrt(st / count);
  std::printf("example scan vs exact ring (%d harmonics): RMS Bn %.3f mT, Bt %.3f mT, "
              "mean Bn %.3f mT, Bt %.3f mT (noise σ = 0.4 mT)\n",
              ring.harmonic_count(), rms_n * 1e3, rms_t * 1e3, mn * 1e3, mt * 1e3);
  // 360 samples of σ = 0.4 mT noise: the sample RMS is 0.4 ± 0.015 mT (1σ).
  EXPECT_NEAR(rms_n, 0.4e-3, 0.06e-3);
  EXPECT_NEAR(rms_t, 0.4e-3, 0.06e-3);
  EXPECT_LT(std::abs(mn), 0.1e-3);
  EXPECT_LT(std::abs(mt), 0.1e-3);
}

TEST(MultipoleRing, ProfileAgreesWithPointEvaluationAndCartesianComponents)
{
  const MultipoleRing ring(example_roller());
  std::vector<double> angles{0.0, 0.5, 1.7, 3.1, 4.8}, Bn, Bt;
  ring.profile(10e-3, angles, Bn, Bt);
  for (size_t k = 0; k < angles.size(); ++k)
  {
    const RingField f = ring.field_polar(10e-3, angles[k]);
    EXPECT_NEAR(Bn[k], f.Br, 1e-14);
    EXPECT_NEAR(Bt[k], f.Btheta, 1e-14);
    EXPECT_NEAR(f.Bx, f.Br * std::cos(angles[k]) - f.Btheta * std::sin(angles[k]), 1e-14);
    EXPECT_NEAR(f.By, f.Br * std::sin(angles[k]) + f.Btheta * std::cos(angles[k]), 1e-14);
  }
}

TEST(MultipoleRing, RejectsBadGeometry)
{
  Roller roller = example_roller();
  roller.shaft_radius = 10e-3; // outside the magnet
  EXPECT_THROW(MultipoleRing{roller}, std::invalid_argument);
  roller = example_roller();
  roller.magnet_radius = 0.0;
  EXPECT_THROW(MultipoleRing{roller}, std::invalid_argument);
  roller = example_roller();
  roller.poles[1].shape_factor = -1.0;
  EXPECT_THROW(MultipoleRing{roller}, std::invalid_argument);
  roller = example_roller();
  roller.poles.clear();
  EXPECT_THROW(MultipoleRing{roller}, std::invalid_argument);
}

TEST(MultipoleRing, RecurrencePathEqualsPerHarmonicEvaluation)
{
  // Orders 1..12 are evaluated with powers by recurrence; adding a zero n = 14 term makes the
  // orders non-consecutive and forces the per-harmonic pow() path. Same field everywhere.
  RingGeometry g;
  g.shaft_radius = 3e-3;
  g.shaft_mu_r = 300.0;
  g.magnet_radius = 9.3e-3;
  g.magnet_mu_r = 1.07;
  std::vector<MagnetisationHarmonic> h;
  for (int n = 1; n <= 12; ++n)
    h.push_back({n, 1e5 / n, -3e4 / (n * n)});
  const MultipoleRing fast(g, h);
  h.push_back({14, 0.0, 0.0});
  const MultipoleRing slow(g, h);
  double worst = 0;
  for (double r : {0.0, 1e-3, 3e-3, 3.0001e-3, 6e-3, 9.3e-3, 9.31e-3, 12e-3, 50e-3})
    for (double t : {0.0, 0.9, 2.8, 4.1})
    {
      const RingField a = fast.field_polar(r, t), b = slow.field_polar(r, t);
      const double scale = std::abs(b.Br) + std::abs(b.Btheta) + 1e-30;
      worst = std::max({worst, std::abs(a.Br - b.Br) / scale, std::abs(a.Btheta - b.Btheta) / scale});
    }
  EXPECT_LT(worst, 1e-12);
}
