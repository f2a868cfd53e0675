// The nip potential at any phase of the latent image (fields/nip_potential_field.h): phase
// weights, band-limited images reproduced exactly by the trigonometric interpolant, the drum's
// surface travel with its spin-up, and the spatial spline against exact fields.
#include "fields/nip_potential_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace magbrush;

namespace {

constexpr double pi = 3.14159265358979323846;
using Phase = NipPotentialField::PhaseInterpolation;

// A window over a gap y ∈ [0, g] with Φ_bias and Φ_image(·; u) given as functions; K samples
// of the image at u_k = k P / K.
NipPotentialGrid nip_grid(int n_x, int n_y, double width, double gap,
                          const std::function<double(double, double)> &bias,
                          const std::function<double(double, double, double)> &image, int K,
                          double period)
{
  NipPotentialGrid g;
  g.bias = sample_cartesian_grid(-0.5 * width, 0.5 * width, n_x, 0.0, gap, n_y, bias);
  g.image_period = period;
  // A planar surface y = 0 moving toward +x: the bottom of a huge drum centred above it
  // (counter-clockwise there is +x).
  g.drum_center = {0.0, 1e3};
  g.drum_radius = 1e3;
  for (int k = 0; k < K; ++k)
  {
    const double u = k * period / K;
    g.image.push_back(sample_cartesian_grid(-0.5 * width, 0.5 * width, n_x, 0.0, gap, n_y,
                                            [&](double x, double y) { return image(x, y, u); })
                        .phi);
  }
  return g;
}

} // namespace

TEST(NipPotentialField, PhaseWeightsSumToOneAndReproduceTheSamples)
{
  for (const Phase phase : {Phase::linear, Phase::trigonometric})
    for (const int K : {1, 2, 5, 8})
    {
      const double P = 2e-3;
      const NipPotentialField f(
        nip_grid(6, 6, 1e-3, 1e-4, [](double, double) { return 0.0; },
                 [](double, double, double) { return 0.0; }, K, K == 1 ? 0.0 : P),
        phase);
      auto w = f.make_phase_weights();
      for (const double u : {-3.7e-3, -1e-9, 0.0, 0.37e-3, 1.0e-3, 1.999e-3, 5.1e-3})
      {
        f.phase_weights(u, w);
        double sum = 0.0;
        for (int m = 0; m < w.count; ++m)
          sum += w.weight[m];
        EXPECT_NEAR(sum, 1.0, 1e-12) << "K = " << K << ", u = " << u;
      }
      for (int k = 0; k < K; ++k) // at a sample (one period later too): that sample alone
      {
        f.phase_weights((k + 3.0 * K) * P / K, w);
        ASSERT_EQ(w.count, 1);
        EXPECT_EQ(w.index[0], k);
        EXPECT_EQ(w.weight[0], 1.0);
      }
    }
}

// An image with harmonics 1 and 2 of the period (and an offset) in u: the trigonometric
// interpolant through K = 6 samples is exact for it at any phase (harmonics < K/2), linear is
// not. The spatial part is a quadratic, which the spline reproduces exactly.
TEST(NipPotentialField, TrigonometricPhaseInterpolationIsExactForABandLimitedImage)
{
  const double P = 1e-3, width = 2e-3, gap = 4e-4;
  const auto bias = [](double x, double y) { return -650.0 * y / 4e-4 + 1e3 * x; };
  const auto A = [](double x, double y) { return 1e8 * x * y + 3.0; };
  const auto B = [](double x, double y) { return 1e8 * (x * x - y * y) - 7.0; };
  const auto image = [&](double x, double y, double u) {
    return 40.0 + A(x, y) * std::cos(2 * pi * u / P) + B(x, y) * std::sin(4 * pi * u / P + 0.3);
  };
  const NipPotentialGrid grid = nip_grid(21, 9, width, gap, bias, image, 6, P);
  const NipPotentialField trig(grid, Phase::trigonometric), lin(grid, Phase::linear);
  auto wt = trig.make_phase_weights(), wl = lin.make_phase_weights();
  double err_trig = 0.0, err_lin = 0.0, scale = 0.0;
  for (const double u : {0.04e-3, 0.31e-3, 0.5e-3, 0.77e-3, -0.2e-3})
  {
    trig.phase_weights(u, wt);
    lin.phase_weights(u, wl);
    for (const double x : {-0.9e-3, -0.13e-3, 0.4e-3})
      for (const double y : {0.0, 0.11e-3, 0.39e-3})
      {
        const Vec3 p{x, y, 5.0};
        const double exact = bias(x, y) + image(x, y, u);
        err_trig = std::max(err_trig, std::abs(trig.potential(p, wt) - exact));
        err_lin = std::max(err_lin, std::abs(lin.potential(p, wl) - exact));
        scale = std::max(scale, std::abs(image(x, y, u) - 40.0));
        // E = −∇Φ, exactly: ∂/∂x of the quadratic parts.
        Vec3 E;
        ASSERT_TRUE(trig.evaluate(p, wt, E));
        const double c = std::cos(2 * pi * u / P), s = std::sin(4 * pi * u / P + 0.3);
        EXPECT_NEAR(E[0], -(1e3 + 1e8 * y * c + 2e8 * x * s), 1e-8 * 1e5);
        EXPECT_NEAR(E[1], -(-650.0 / 4e-4 + 1e8 * x * c - 2e8 * y * s), 1e-8 * 1e6);
        EXPECT_EQ(E[2], 0.0);
      }
  }
  std::printf("band-limited image: max |ΔΦ| trigonometric %.2e V, linear %.2e V (image scale %.3g V)\n",
              err_trig, err_lin, scale);
  EXPECT_LT(err_trig, 1e-10 * scale);
  EXPECT_GT(err_lin, 1e-3 * scale); // linear in phase cannot follow the second harmonic
}

// The drum's surface travels u(t) = R Θ(t): Θ = ω t²/(2T) during the spin-up ramp of the drum
// wall's speed (ω t/T), ω (t − T/2) after it, nothing before t = 0 (settling). Against the
// integral of the wall's speed by the trapezoidal rule (exact for a piecewise-linear speed).
TEST(NipPotentialField, SurfaceTravelIsTheIntegralOfTheDrumSpeed)
{
  Drum d;
  d.present = true;
  d.radius = 15e-3;
  d.rpm = -170.0;
  d.spin_up_time = 2e-3;
  const auto speed = [&](double t) {
    return t <= 0.0 ? 0.0 : d.omega() * d.radius * std::min(1.0, t / d.spin_up_time);
  };
  double integral = 0.0, t = 0.0;
  const double dt = 1e-6;
  for (int k = 0; k < 5000; ++k, t += dt)
  {
    integral += 0.5 * dt * (speed(t) + speed(t + dt));
    if ((k + 1) % 500 == 0)
    {
      EXPECT_NEAR(NipPotentialField::surface_travel(d, t + dt), integral, 1e-12 * d.radius)
        << "t = " << t + dt;
    }
  }
  EXPECT_EQ(NipPotentialField::surface_travel(d, -1e-3), 0.0);
  d.spin_up_time = 0.0;
  EXPECT_DOUBLE_EQ(NipPotentialField::surface_travel(d, 1e-3), d.omega() * d.radius * 1e-3);
}

// Outside the window: E = 0, false, Φ NaN; edges included.
TEST(NipPotentialField, OutsideTheWindowTheFieldIsZero)
{
  const NipPotentialField f(nip_grid(8, 8, 1e-3, 1e-4, [](double x, double) { return 1e6 * x; },
                                     [](double, double, double) { return 0.0; }, 1, 0.0));
  auto w = f.make_phase_weights();
  f.phase_weights(0.0, w);
  Vec3 E;
  EXPECT_TRUE(f.evaluate({0.5e-3, 1e-4, 0.0}, w, E));
  EXPECT_NEAR(E[0], -1e6, 1e-6);
  EXPECT_FALSE(f.evaluate({0.5e-3 + 1e-9, 0.5e-4, 0.0}, w, E));
  EXPECT_EQ(E[0], 0.0);
  EXPECT_EQ(E[1], 0.0);
  EXPECT_TRUE(std::isnan(f.potential({0.0, -1e-9, 0.0}, w)));
}
