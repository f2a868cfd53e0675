// Verification of the pole fit on scans it has never seen: not made by the model it fits.
//
// The fit's forward model is the Fourier series of the exact multipole ring (pole_fit.h). A
// scan made by that same series would only show that the fit inverts its own model (an
// "inverse crime"). The scans here are made by a different route: the magnet's field by direct
// quadrature of its magnetic charges (for μ_r = 1 everywhere, the field of a radially
// magnetised annulus is exactly that of the volume charge ρ = −∇·M = −M(θ)/r and the surface
// charges ±M(θ) on its outer and inner rims), on another roller than the example one (six
// poles, a 12 mm magnet around a 4 mm air core, probe at 13 mm), with a shape factor per pole,
// an encoder offset and probe noise.
//
// Checked:
//  * the charge quadrature agrees with the exact ring (so the test is about the fit, not about
//    two models of different magnets);
//  * the noise estimated from the scan is within 20 % of the true noise;
//  * with a shape factor per pole in the scan, `automatic` chooses per-pole and recovers the
//    poles; the shared fit leaves a residual far above the noise and says so;
//  * the comparison after the fit applies the fitted encoder offset: its RMS is the fit's
//    residual;
//  * a scan with one shape factor for all keeps `shared` under `automatic`;
//  * the F-test's distribution against closed forms.
// The scan's angular origin as a case key (measured_flux_angle_origin) leaves the field hash
// alone.
#include "calibration/nested_model_test.h"
#include "calibration/pole_fit.h"
#include "calibration/scan_noise.h"
#include "case/case_hash.h"
#include "case/case_parser.h"
#include "fields/multipole_ring.h"
#include "tests/calibration/unseen_roller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace magbrush;
using namespace magbrush::unseen;

namespace {

constexpr double mu0 = 4e-7 * M_PI;

double magnetisation(const Roller &roller, double theta)
{
  double m = 0.0;
  for (const Pole &p : roller.poles)
  {
    const double u = wrap_pm_pi(theta - p.angle);
    m += p.strength * std::exp(-p.shape_factor * u * u);
  }
  return m;
}

// B = μ0 H outside the magnet from its magnetic charges, H(x) = (1/2π) ∫ q (x − x')/|x − x'|²:
// periodic trapezoidal rule in θ' (spectrally accurate), 5-point Gauss–Legendre on 24 radial
// slices for the volume charge. Returns (Bn, Bt) = (B_r, B_θ) at (r, θ).
struct ChargeQuadrature
{
  explicit ChargeQuadrature(const Roller &roller, int angular_points = 2048)
      : inner(roller.shaft_radius), outer(roller.magnet_radius)
  {
    const double gl_x[] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640,
                           0.9061798459386640};
    const double gl_w[] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                           0.2369268850561891, 0.2369268850561891};
    const int slices = 24;
    const double h = (outer - inner) / slices;
    for (int s = 0; s < slices; ++s)
      for (int g = 0; g < 5; ++g)
      {
        radial_node.push_back(inner + h * (s + 0.5 + 0.5 * gl_x[g]));
        radial_weight.push_back(0.5 * h * gl_w[g]);
      }
    for (int j = 0; j < angular_points; ++j)
    {
      const double t = 2 * M_PI * j / angular_points;
      angle.push_back(t);
      M_dtheta.push_back(magnetisation(roller, t) * 2 * M_PI / angular_points);
    }
  }

  void field(double r, double theta, double &Bn, double &Bt) const
  {
    const double x = r * std::cos(theta), y = r * std::sin(theta);
    double Hx = 0.0, Hy = 0.0;
    const auto add = [&](double weight, double rho, double t) {
      const double dx = x - rho * std::cos(t), dy = y - rho * std::sin(t);
      const double d2 = dx * dx + dy * dy;
      Hx += weight * dx / d2;
      Hy += weight * dy / d2;
    };
    for (size_t j = 0; j < angle.size(); ++j)
    {
      add(M_dtheta[j] * outer, outer, angle[j]);   // σ = +M on the outer rim (dl = R dθ)
      if (inner > 0.0)
        add(-M_dtheta[j] * inner, inner, angle[j]); // σ = −M on the inner rim
      for (size_t k = 0; k < radial_node.size(); ++k) // ρ dA = −(M/r') r' dr' dθ'
        add(-M_dtheta[j] * radial_weight[k], radial_node[k], angle[j]);
    }
    Hx /= 2 * M_PI;
    Hy /= 2 * M_PI;
    Bn = mu0 * (Hx * std::cos(theta) + Hy * std::sin(theta));
    Bt = mu0 * (-Hx * std::sin(theta) + Hy * std::cos(theta));
  }

  double inner, outer;
  std::vector<double> radial_node, radial_weight, angle, M_dtheta;
};

// A gaussmeter scan of `roller`: 0.5° steps over the full turn, read by an encoder whose zero
// is `offset` behind the roller's (scan angle = roller angle − offset), noise σ on each
// component (seeded, so the test is repeatable).
FluxScan scan_of(const Roller &roller, double offset, double sigma, unsigned seed)
{
  const ChargeQuadrature magnet(roller);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  FluxScan s;
  s.source = "charge quadrature";
  for (int k = 0; k < 720; ++k)
  {
    const double scan_angle = k * 0.5 * deg;
    double Bn, Bt;
    magnet.field(probe_radius, scan_angle + offset, Bn, Bt);
    s.angle.push_back(scan_angle);
    s.Bn.push_back(Bn + noise(rng));
    s.Bt.push_back(Bt + noise(rng));
  }
  return s;
}

} // namespace

TEST(UnseenScan, ChargeQuadratureAgreesWithTheExactRing)
{
  const Roller truth = true_roller(per_pole_alpha);
  const FluxScan exact_scan = scan_of(truth, 0.0, 0.0, 1);
  std::vector<double> Bn, Bt;
  MultipoleRing(truth).profile(probe_radius, exact_scan.angle, Bn, Bt);
  double worst = 0.0, peak = 0.0;
  for (size_t k = 0; k < Bn.size(); ++k)
  {
    worst = std::max(worst, std::hypot(exact_scan.Bn[k] - Bn[k], exact_scan.Bt[k] - Bt[k]));
    peak = std::max(peak, std::hypot(Bn[k], Bt[k]));
  }
  std::printf("charge quadrature against the exact ring: max |ΔB| = %.2e T (%.1e of the peak %.1f mT)\n",
              worst, worst / peak, peak * 1e3);
  EXPECT_LT(worst / peak, 1e-6);
}

TEST(UnseenScan, NoiseEstimateFromTheScanItself)
{
  const Roller truth = true_roller(per_pole_alpha);
  // Without noise the estimate is what the smooth profile leaks into it.
  const ScanNoise clean = estimate_scan_noise(scan_of(truth, encoder_offset, 0.0, 1));
  std::printf("noise-free scan: estimated noise Bn %.2e, Bt %.2e mT\n", clean.Bn * 1e3, clean.Bt * 1e3);
  EXPECT_LT(clean.Bn, 0.01e-3);
  EXPECT_LT(clean.Bt, 0.01e-3);
  for (double sigma : {0.1e-3, 0.5e-3, 2e-3})
  {
    const ScanNoise n = estimate_scan_noise(scan_of(truth, encoder_offset, sigma, 7));
    std::printf("true noise %.2f mT: estimated Bn %.3f, Bt %.3f mT\n", sigma * 1e3, n.Bn * 1e3,
                n.Bt * 1e3);
    EXPECT_NEAR(n.Bn / sigma, 1.0, 0.2);
    EXPECT_NEAR(n.Bt / sigma, 1.0, 0.2);
  }
}

TEST(UnseenScan, PerPoleShapesAreChosenAndRecovered)
{
  const Roller truth = true_roller(per_pole_alpha);
  const FluxScan scan = scan_of(truth, encoder_offset, noise_sigma, 3);

  PoleFitOptions shared_only;
  shared_only.shape = PoleFitOptions::Shape::shared;
  const PoleFitResult shared = fit_poles(design_roller(), scan, probe_radius, shared_only);
  const PoleFitResult fit = fit_poles(design_roller(), scan, probe_radius); // automatic
  ASSERT_TRUE(fit.converged) << fit.status;
  const Worst w = worst_deviation(fit, truth);
  std::printf("shared α: residual %.3f mT = %.2f × the noise estimate %.3f mT\n", shared.rms * 1e3,
              shared.rms / shared.noise_rms, shared.noise_rms * 1e3);
  std::printf("automatic: %s; %s\n", shape_name(fit.shape).c_str(),
              fit.shape_selection.reason.c_str());
  std::printf("  residual %.4f mT, noise estimate %.4f mT (true %.2f); worst pole: angle %.4f deg, "
              "strength %.3f %%, shape %.2f %%; offset %.4f deg (true %.2f)\n",
              fit.rms * 1e3, fit.noise_rms * 1e3, noise_sigma * 1e3, w.angle / deg,
              100 * w.strength, 100 * w.shape, fit.offset / deg, encoder_offset / deg);

  // The shared fit is far from the noise, and says so, pointing to per-pole shapes.
  EXPECT_GT(shared.rms, residual_far_above_noise * shared.noise_rms);
  EXPECT_NE(residual_warning(shared).find("--fit-shape per-pole"), std::string::npos)
      << residual_warning(shared);

  // Automatic chooses per-pole, clearly, and the fit reaches the noise.
  EXPECT_EQ(fit.shape, PoleFitOptions::Shape::per_pole);
  EXPECT_TRUE(fit.shape_selection.automatic);
  EXPECT_LT(fit.shape_selection.test.p_value, 1e-6);
  EXPECT_NEAR(fit.rms / noise_sigma, 1.0, 0.05);
  EXPECT_TRUE(residual_warning(fit).empty()) << residual_warning(fit);
  EXPECT_NEAR(fit.noise_rms / noise_sigma, 1.0, 0.2);
  EXPECT_LT(w.angle, 0.1 * deg);
  EXPECT_LT(w.strength, 0.01);
  EXPECT_LT(w.shape, 0.03);
  EXPECT_NEAR(fit.offset, encoder_offset, 0.05 * deg);

  // The comparison after the fit sees the scan as the fit did (offset applied): same RMS.
  const FluxComparison after = compare_with_fitted_model(scan, fit, probe_radius);
  std::printf("comparison after the fit: RMS %.4f mT (fit residual %.4f mT)\n",
              combined_rms(after) * 1e3, fit.rms * 1e3);
  EXPECT_NEAR(combined_rms(after) / fit.rms, 1.0, 0.02);
}

TEST(UnseenScan, SharedShapeScanKeepsShared)
{
  const Roller truth = true_roller(shared_alpha);
  for (unsigned seed : {5u, 6u, 7u})
  {
    const FluxScan scan = scan_of(truth, encoder_offset, noise_sigma, seed);
    const PoleFitResult fit = fit_poles(design_roller(), scan, probe_radius); // automatic
    ASSERT_TRUE(fit.converged) << fit.status;
    const Worst w = worst_deviation(fit, truth);
    std::printf("seed %u: %s (p = %.3g); residual %.4f mT, noise %.4f mT; worst angle %.4f deg, "
                "strength %.3f %%, shape %.2f %%\n",
                seed, shape_name(fit.shape).c_str(), fit.shape_selection.test.p_value,
                fit.rms * 1e3, fit.noise_rms * 1e3, w.angle / deg, 100 * w.strength, 100 * w.shape);
    EXPECT_EQ(fit.shape, PoleFitOptions::Shape::shared) << fit.shape_selection.reason;
    EXPECT_TRUE(residual_warning(fit).empty()) << residual_warning(fit);
    EXPECT_LT(w.angle, 0.1 * deg);
    EXPECT_LT(w.strength, 0.01);
    EXPECT_LT(w.shape, 0.01);
  }
}

TEST(NestedModelTest, MatchesClosedForms)
{
  // I_x(1, 1) = x, I_x(a, 1) = x^a, I_x(1, b) = 1 − (1 − x)^b.
  for (double x : {0.01, 0.3, 0.7, 0.99})
  {
    EXPECT_NEAR(regularized_incomplete_beta(x, 1, 1), x, 1e-13);
    EXPECT_NEAR(regularized_incomplete_beta(x, 3.5, 1), std::pow(x, 3.5), 1e-13);
    EXPECT_NEAR(regularized_incomplete_beta(x, 1, 700), 1 - std::pow(1 - x, 700), 1e-12);
  }
  // F(2, d2): P(X ≥ F) = (1 + 2F/d2)^(−d2/2), also far in the tail.
  for (double F : {0.5, 3.0, 20.0})
  {
    const double d2 = 1400;
    const double exact = std::pow(1 + 2 * F / d2, -d2 / 2);
    EXPECT_NEAR(f_distribution_upper_tail(F, 2, d2) / exact, 1.0, 1e-10) << F;
  }
  // Nested fits: no improvement is p = 1, an exact larger model is p = 0.
  EXPECT_DOUBLE_EQ(compare_nested_models(1.0, 11, 1.0, 15, 720).p_value, 1.0);
  EXPECT_DOUBLE_EQ(compare_nested_models(1.0, 11, 0.0, 15, 720).p_value, 0.0);
}

TEST(ScanAngleOrigin, IsACaseKeyThatChangesNoField)
{
  const std::string roller_case = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_full_roller.yaml";
  const Case plain = load_case(roller_case);
  const Case turned = load_case(roller_case, {"measured_flux_angle_origin=3.5deg"});
  EXPECT_DOUBLE_EQ(plain.measured_flux_angle_origin, 0.0);
  EXPECT_NEAR(turned.measured_flux_angle_origin, 3.5 * deg, 1e-15);
  EXPECT_EQ(field_hash(plain, FieldKind::magnetic), field_hash(turned, FieldKind::magnetic));
  EXPECT_EQ(field_hash(plain, FieldKind::electric), field_hash(turned, FieldKind::electric));
}
