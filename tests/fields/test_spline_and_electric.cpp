// The cubic-spline node data shared by both interpolators, and the electric interpolator
// against an exact harmonic potential.
#include "fields/cartesian_field_interpolator.h"
#include "fields/field_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace magbrush;

// Not-a-knot splines reproduce cubics exactly, slopes included.
TEST(Spline, NotAKnotIsExactForCubics)
{
  const int n = 9;
  std::vector<double> f(n), m(n);
  const auto P = [](double t) { return 0.3 * t * t * t - 1.2 * t * t + 0.7 * t - 2.0; };
  const auto dP = [](double t) { return 0.9 * t * t - 2.4 * t + 0.7; };
  for (int k = 0; k < n; ++k)
    f[k] = P(k);
  spline::slopes_not_a_knot(f.data(), m.data(), n, 1);
  for (int k = 0; k < n; ++k)
    EXPECT_NEAR(m[k], dP(k), 1e-12) << "k = " << k;
  EXPECT_THROW(spline::slopes_not_a_knot(f.data(), m.data(), 3, 1), FieldGridError);
}

// The periodic spline of sin(kθ) has slopes k cos(kθ) up to O(h⁴) (here h = 2π/n per index).
TEST(Spline, PeriodicSlopesConvergeAtFourthOrder)
{
  double previous = 0.0;
  for (int n : {32, 64, 128})
  {
    std::vector<double> f(n), m(n);
    const double h = 2 * M_PI / n;
    for (int j = 0; j < n; ++j)
      f[j] = std::sin(3 * j * h + 0.2);
    spline::slopes_periodic(f.data(), m.data(), n, 1);
    double err = 0.0;
    for (int j = 0; j < n; ++j)
      err = std::max(err, std::abs(m[j] / h - 3 * std::cos(3 * j * h + 0.2)));
    if (previous > 0)
    {
      EXPECT_GT(std::log2(previous / err), 3.7) << "n = " << n;
    }
    previous = err;
  }
}

namespace {
// A harmonic potential with a uniform part: Φ = V0 e^{−k y} cos(k x) + E0 y.
constexpr double V0 = 300.0, k = 2 * M_PI / 400e-6, E0 = -1.5e6;
double phi_exact(double x, double y) { return V0 * std::exp(-k * y) * std::cos(k * x) + E0 * y; }
std::array<double, 2> E_exact(double x, double y)
{
  return {V0 * k * std::exp(-k * y) * std::sin(k * x),
          V0 * k * std::exp(-k * y) * std::cos(k * x) - E0};
}
CartesianGrid window(int cells)
{
  return sample_cartesian_grid(-300e-6, 300e-6, cells + 1, 0.0, 400e-6, cells + 1, phi_exact);
}
} // namespace

// E = −∇Φ converges at third order (first derivative of a cubic spline).
TEST(CartesianFieldInterpolator, ElectricFieldConvergesAtThirdOrder)
{
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ux(-300e-6, 300e-6), uy(0.0, 400e-6);
  std::vector<std::array<double, 2>> points(3000);
  for (auto &p : points)
    p = {ux(rng), uy(rng)};
  std::vector<double> errors;
  for (int cells : {24, 48, 96})
  {
    CartesianFieldInterpolator interp(window(cells));
    double err = 0, scale = 0, phi_err = 0;
    for (const auto &p : points)
    {
      Vec3 E;
      ASSERT_TRUE(interp.evaluate({p[0], p[1], 1.0}, E));
      const auto e = E_exact(p[0], p[1]);
      err = std::max(err, std::hypot(E[0] - e[0], E[1] - e[1]));
      scale = std::max(scale, std::hypot(e[0], e[1]));
      phi_err = std::max(phi_err, std::abs(interp.potential({p[0], p[1], 0}) - phi_exact(p[0], p[1])));
      EXPECT_EQ(E[2], 0.0);
    }
    errors.push_back(err / scale);
    std::printf("  %2d cells: max |E| error %.3e (relative), max phi error %.3e V\n", cells,
                err / scale, phi_err);
  }
  for (size_t l = 1; l < errors.size(); ++l)
  {
    const double order = std::log2(errors[l - 1] / errors[l]);
    std::printf("  observed order of E: %.2f\n", order);
    EXPECT_GT(order, 2.7);
    EXPECT_LT(order, 3.6);
  }
  EXPECT_LT(errors.back(), 5e-5);
}

// Outside the window: E = 0 and `false`; Φ is NaN. Edges belong to the window.
TEST(CartesianFieldInterpolator, OutsideTheWindowTheFieldIsZero)
{
  CartesianFieldInterpolator interp(window(16));
  Vec3 E{1, 1, 1};
  EXPECT_FALSE(interp.evaluate({301e-6, 100e-6, 0}, E));
  EXPECT_EQ(E, (Vec3{0, 0, 0}));
  EXPECT_FALSE(interp.evaluate({0, -1e-9, 0}, E));
  EXPECT_TRUE(std::isnan(interp.potential({0, 401e-6, 0})));
  EXPECT_TRUE(interp.evaluate({300e-6, 400e-6, 0}, E)); // the far corner
  const auto e = E_exact(300e-6, 400e-6);
  EXPECT_NEAR(E[0], e[0], 1e-2 * std::hypot(e[0], e[1]));
  EXPECT_NEAR(E[1], e[1], 1e-2 * std::hypot(e[0], e[1]));
  EXPECT_NEAR(interp.potential({-300e-6, 0, 0}), phi_exact(-300e-6, 0), 1e-9);
}
