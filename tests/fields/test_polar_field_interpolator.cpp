// The magnetic interpolator against the exact multipole-ring field: accuracy and observed
// convergence orders, exact divergence, curl to interpolation accuracy, the periodic seam,
// the multipole tail beyond the grid and the behaviour inside the sleeve.
#include "tests/fields/exact_multipole.h"
#include "fields/polar_field_interpolator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace magbrush;
using namespace magbrush::testing;

namespace {

constexpr double r_min = 12.5e-3, r_max = 16e-3;

// A few harmonics with phases, like a roller but cheap: the convergence regime sets in on
// small grids.
MultipoleField test_field()
{
  return MultipoleField(4e-3, 11.5e-3,
                        {{2, 80e3, 0.3}, {3, -150e3, 1.1}, {5, 200e3, -0.4}, {7, 60e3, 2.0}});
}

PolarGrid grid_for(const MultipoleField &f, int cells_r, int n_theta)
{
  return sample_polar_grid(r_min, r_max, cells_r + 1, n_theta,
                           [&](double x, double y) { return f.A(x, y); });
}

std::array<double, 2> grad_B2(const std::array<double, 2> &B,
                              const std::array<std::array<double, 2>, 2> &g)
{
  return {2 * (B[0] * g[0][0] + B[1] * g[1][0]), 2 * (B[0] * g[0][1] + B[1] * g[1][1])};
}

struct Errors
{
  double B = 0, gradB = 0, gradB2 = 0, curl = 0, div = 0; // max errors, relative to max exact
};

Errors measure(const PolarFieldInterpolator &interp, const MultipoleField &f,
               const std::vector<std::array<double, 2>> &points)
{
  Errors e;
  double B_max = 0, g_max = 0, g2_max = 0;
  for (const auto &p : points)
  {
    const auto exact = f.B(p[0], p[1]);
    Vec3 B;
    std::array<Vec3, 3> g;
    interp.evaluate({p[0], p[1], 0.0}, B, g);
    const std::array<std::array<double, 2>, 2> gi = {{{g[0][0], g[0][1]}, {g[1][0], g[1][1]}}};
    const auto G2 = grad_B2(exact.B, exact.gradB), G2i = grad_B2({B[0], B[1]}, gi);
    B_max = std::max(B_max, std::hypot(exact.B[0], exact.B[1]));
    e.B = std::max(e.B, std::hypot(B[0] - exact.B[0], B[1] - exact.B[1]));
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
      {
        g_max = std::max(g_max, std::abs(exact.gradB[i][j]));
        e.gradB = std::max(e.gradB, std::abs(gi[i][j] - exact.gradB[i][j]));
      }
    g2_max = std::max(g2_max, std::hypot(G2[0], G2[1]));
    e.gradB2 = std::max(e.gradB2, std::hypot(G2i[0] - G2[0], G2i[1] - G2[1]));
    e.curl = std::max(e.curl, std::abs(g[1][0] - g[0][1]));
    e.div = std::max(e.div, std::abs(g[0][0] + g[1][1]));
    EXPECT_EQ(B[2], 0.0);
    EXPECT_EQ(g[2][0], 0.0);
    EXPECT_EQ(g[0][2], 0.0);
  }
  e.B /= B_max;
  e.gradB /= g_max;
  e.gradB2 /= g2_max;
  e.curl /= g_max;
  e.div /= g_max;
  return e;
}

} // namespace

// The reference itself: curl(A ẑ) of the potential we derived equals the ring's field
// formula, and ∇B by central differences matches; the fast series agrees with both.
TEST(ExactMultipole, FieldIsCurlOfPotentialAndGradientMatches)
{
  const MultipoleField f = test_field();
  const double h = 1e-7;
  for (const auto &p : sample_annulus(r_min, r_max, 50))
  {
    const double x = p[0], y = p[1];
    const auto e = f.B_design_formula(x, y);
    const double Bx = (f.A(x, y + h) - f.A(x, y - h)) / (2 * h);
    const double By = -(f.A(x + h, y) - f.A(x - h, y)) / (2 * h);
    const double scale = std::hypot(e.B[0], e.B[1]) + 1e-3;
    EXPECT_NEAR(Bx, e.B[0], 1e-6 * scale);
    EXPECT_NEAR(By, e.B[1], 1e-6 * scale);
    const auto ex = f.B_design_formula(x + h, y), wx = f.B_design_formula(x - h, y);
    const auto ny = f.B_design_formula(x, y + h), sy = f.B_design_formula(x, y - h);
    const auto fast = f.B(x, y);
    for (int i = 0; i < 2; ++i)
    {
      EXPECT_NEAR((ex.B[i] - wx.B[i]) / (2 * h), e.gradB[i][0], 1e-6 * scale / r_min);
      EXPECT_NEAR((ny.B[i] - sy.B[i]) / (2 * h), e.gradB[i][1], 1e-6 * scale / r_min);
      EXPECT_NEAR(fast.B[i], e.B[i], 1e-12 * scale);
      for (int j = 0; j < 2; ++j)
        EXPECT_NEAR(fast.gradB[i][j], e.gradB[i][j], 1e-12 * scale / r_min);
    }
  }
}

// The Gaussian-pole roller's Fourier series reproduces the pole model it comes from: the
// sleeve field under the strongest pole (S1 at 0°) points inward.
TEST(ExactMultipole, RollerLikeFieldHasItsPolesWhereTheModelPutsThem)
{
  const MultipoleField f = roller_like_field();
  const auto s1 = f.B(r_min, 0.0);
  EXPECT_LT(s1.B[0], -0.05); // radially inward, tens of mT
  const auto n1 = f.B(r_min * std::cos(72 * M_PI / 180), r_min * std::sin(72 * M_PI / 180));
  EXPECT_GT(n1.B[0] * std::cos(72 * M_PI / 180) + n1.B[1] * std::sin(72 * M_PI / 180), 0.02);
}

// Errors on grids of spacing h, h/2, h/4 and the observed orders: B = O(h³) (first
// derivatives of a cubic spline), ∇B and ∇|B|² = O(h²).
TEST(PolarFieldInterpolator, ConvergesAtTheOrderOfTheCubicSpline)
{
  const MultipoleField f = test_field();
  const auto points = sample_annulus(r_min, r_max, 4000);
  std::vector<Errors> errors;
  for (int level = 0; level < 3; ++level)
  {
    const int k = 1 << level;
    PolarFieldInterpolator interp(grid_for(f, 8 * k, 96 * k));
    errors.push_back(measure(interp, f, points));
    std::printf("  grid %3d x %4d: |B| err %.3e  gradB err %.3e  grad|B|^2 err %.3e  curl %.3e  div %.1e\n",
                8 * k + 1, 96 * k, errors.back().B, errors.back().gradB, errors.back().gradB2,
                errors.back().curl, errors.back().div);
  }
  for (int level = 1; level < 3; ++level)
  {
    const double order_B = std::log2(errors[level - 1].B / errors[level].B);
    const double order_G2 = std::log2(errors[level - 1].gradB2 / errors[level].gradB2);
    const double order_curl = std::log2(errors[level - 1].curl / errors[level].curl);
    std::printf("  observed order: B %.2f  grad|B|^2 %.2f  curl %.2f\n", order_B, order_G2,
                order_curl);
    EXPECT_GT(order_B, 2.7);
    EXPECT_LT(order_B, 3.6);
    EXPECT_GT(order_G2, 1.8);
    EXPECT_LT(order_G2, 2.6);
    EXPECT_GT(order_curl, 1.8);
  }
  // And the finest grid is accurate in absolute terms.
  EXPECT_LT(errors[2].B, 2e-5);
  EXPECT_LT(errors[2].gradB2, 2e-3);
}

// The figures quoted for the default grid (field.grid_radial_spacing = 50 µm, angular 0.25°;
// docs/field_grid_format.md): on the roller-like field of bench_field_grid (5 Gaussian poles,
// 40,000 random points over the annulus) the errors are 2.4e-6 in B and 3.2e-4 in ∇|B|²,
// relative to their maxima. Asserted with 10 % headroom over the measured values.
TEST(PolarFieldInterpolator, DefaultSpacingMeetsTheQuotedAccuracy)
{
  const MultipoleField f = roller_like_field();
  const double dr = 50e-6, dtheta = 0.25 * M_PI / 180.0;
  const int n_r = 1 + static_cast<int>(std::ceil((r_max - r_min) / dr - 1e-9));
  const int n_theta = static_cast<int>(std::ceil(2 * M_PI / dtheta - 1e-9));
  PolarFieldInterpolator interp(sample_polar_grid(r_min, r_max, n_r, n_theta,
                                                  [&](double x, double y) { return f.A(x, y); }));
  const Errors e = measure(interp, f, sample_annulus(r_min, r_max, 40000, 2024));
  std::printf("default grid %d x %d: |B| err %.3e  grad|B|^2 err %.3e\n", n_r, n_theta, e.B, e.gradB2);
  EXPECT_LT(e.B, 2.7e-6);
  EXPECT_LT(e.gradB2, 3.5e-4);
}

// ∇·B = ∂²A/∂x∂y − ∂²A/∂y∂x cancels identically; curl B = −∇²A is an interpolation error.
TEST(PolarFieldInterpolator, FieldIsDivergenceFreeExactlyAndCurlFreeToInterpolationAccuracy)
{
  const MultipoleField f = test_field();
  PolarFieldInterpolator interp(grid_for(f, 32, 384));
  const Errors e = measure(interp, f, sample_annulus(r_min, r_max, 2000, 7));
  EXPECT_LT(e.div, 1e-13);
  EXPECT_LT(e.curl, 5e-3);
  EXPECT_LT(e.curl, 3 * e.gradB); // the curl is of the size of the gradient error, no more
}

// θ = 0 and θ = 2π are the same line: the field and its gradient agree on both sides.
TEST(PolarFieldInterpolator, PeriodicSeamIsContinuous)
{
  const MultipoleField f = test_field();
  const PolarGrid g = grid_for(f, 8, 48);
  PolarFieldInterpolator interp(g);
  for (double r : {r_min, 0.5 * (r_min + r_max), r_max - 0.3 * g.dr()})
  {
    Vec3 B_below, B_above, B_on;
    std::array<Vec3, 3> g_below, g_above, g_on;
    const double eps = 1e-12 * r;
    interp.evaluate({r, -eps, 0}, B_below, g_below); // θ just below 2π
    interp.evaluate({r, eps, 0}, B_above, g_above);  // θ just above 0
    interp.evaluate({r, 0.0, 0}, B_on, g_on);
    const double scale_B = std::hypot(B_on[0], B_on[1]), scale_g = std::abs(g_on[0][0]) +
                                                                    std::abs(g_on[0][1]) +
                                                                    std::abs(g_on[1][0]);
    for (int i = 0; i < 2; ++i)
    {
      EXPECT_NEAR(B_below[i], B_above[i], 1e-9 * scale_B) << "r = " << r;
      EXPECT_NEAR(B_on[i], B_above[i], 1e-9 * scale_B) << "r = " << r;
      for (int j = 0; j < 2; ++j)
        EXPECT_NEAR(g_below[i][j], g_above[i][j], 1e-8 * scale_g) << "r = " << r;
    }
    // Not merely continuous: as accurate at the seam as anywhere (coarse grid here).
    const auto exact = f.B(r, 0.0);
    EXPECT_NEAR(B_on[0], exact.B[0], 2e-3 * scale_B);
    EXPECT_NEAR(B_on[1], exact.B[1], 2e-3 * scale_B);
  }
  // ∇B is continuous across an ordinary cell boundary as well (C2 spline of A).
  const double th = 5 * g.dtheta(), r = 0.5 * (r_min + r_max), d = 1e-10;
  Vec3 B1, B2;
  std::array<Vec3, 3> g1, g2;
  interp.evaluate({r * std::cos(th - d), r * std::sin(th - d), 0}, B1, g1);
  interp.evaluate({r * std::cos(th + d), r * std::sin(th + d), 0}, B2, g2);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      EXPECT_NEAR(g1[i][j], g2[i][j], 1e-6 * (std::abs(g1[0][0]) + std::abs(g1[0][1])));
}

// Beyond r_max the exterior multipole continuation of the outer ring: exact for a field
// with no sources outside, continuous with the grid at r_max, decaying, never zero.
TEST(PolarFieldInterpolator, TailBeyondTheGridIsTheDecayingMultipoleField)
{
  const MultipoleField f = test_field();
  PolarFieldInterpolator interp(grid_for(f, 32, 384));
  EXPECT_GE(interp.tail_harmonics(), 7);
  for (double factor : {1.0 + 1e-9, 1.05, 1.5, 3.0})
    for (double th : {0.1, 1.7, 4.0})
    {
      const double r = factor * r_max, x = r * std::cos(th), y = r * std::sin(th);
      const auto exact = f.B(x, y);
      Vec3 B;
      std::array<Vec3, 3> g;
      interp.evaluate({x, y, 0}, B, g);
      // Scale: the largest field on this circle (the exact field's first harmonic bound).
      double scale = 0, gscale = 0;
      for (int k = 0; k < 64; ++k)
      {
        const auto e = f.B(r * std::cos(2 * M_PI * k / 64), r * std::sin(2 * M_PI * k / 64));
        scale = std::max(scale, std::hypot(e.B[0], e.B[1]));
        gscale = std::max(gscale, std::abs(e.gradB[0][0]) + std::abs(e.gradB[0][1]));
      }
      EXPECT_NEAR(B[0], exact.B[0], 1e-5 * scale) << "r/r_max = " << factor;
      EXPECT_NEAR(B[1], exact.B[1], 1e-5 * scale) << "r/r_max = " << factor;
      EXPECT_NEAR(g[0][0], exact.gradB[0][0], 1e-3 * gscale) << "r/r_max = " << factor;
      EXPECT_NEAR(g[0][1], exact.gradB[0][1], 1e-3 * gscale) << "r/r_max = " << factor;
      EXPECT_NEAR(g[0][0] + g[1][1], 0.0, 1e-12 * gscale);
    }
  // Continuity across r_max: just inside (spline) and just outside (multipole).
  for (double th : {0.0, 0.9, 3.3})
  {
    Vec3 Bi, Bo;
    std::array<Vec3, 3> gi, go;
    const double c = std::cos(th), s = std::sin(th);
    interp.evaluate({r_max * (1 - 1e-12) * c, r_max * (1 - 1e-12) * s, 0}, Bi, gi);
    interp.evaluate({r_max * (1 + 1e-12) * c, r_max * (1 + 1e-12) * s, 0}, Bo, go);
    const double scale = std::hypot(Bi[0], Bi[1]) + 1e-3;
    EXPECT_NEAR(Bi[0], Bo[0], 1e-5 * scale);
    EXPECT_NEAR(Bi[1], Bo[1], 1e-5 * scale);
  }
}

// Inside the sleeve the field is not defined: a clear error, or `false` from try_evaluate.
// Half a cell of tolerance covers particles pressed into the sleeve by their contact overlap.
TEST(PolarFieldInterpolator, InsideTheSleeveIsAnErrorBeyondHalfACell)
{
  const MultipoleField f = test_field();
  const PolarGrid g = grid_for(f, 16, 192);
  PolarFieldInterpolator interp(g);
  Vec3 B;
  std::array<Vec3, 3> gB;
  const double r_in = r_min - 0.6 * g.dr();
  try
  {
    interp.evaluate({0.0, r_in, 0.0}, B, gB);
    FAIL() << "expected FieldLookupError";
  }
  catch (const FieldLookupError &e)
  {
    EXPECT_NE(std::string(e.what()).find("inside the field grid's inner radius"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(interp.try_evaluate({0.0, r_in, 0.0}, B, gB));
  EXPECT_FALSE(interp.try_evaluate({std::nan(""), 0.0, 0.0}, B, gB));
  try
  {
    interp.evaluate({std::nan(""), 0.0, 0.0}, B, gB);
    FAIL() << "expected FieldLookupError";
  }
  catch (const FieldLookupError &e)
  {
    EXPECT_NE(std::string(e.what()).find("non-finite position"), std::string::npos) << e.what();
  }
  EXPECT_EQ(B[0], 0.0);
  EXPECT_EQ(gB[1][0], 0.0);
  // Within the tolerance band: the boundary cell's cubic, still close to the exact field.
  const double r_near = r_min - 0.2 * g.dr();
  ASSERT_TRUE(interp.try_evaluate({0.0, r_near, 0.0}, B, gB));
  const auto exact = f.B(0.0, r_near);
  EXPECT_NEAR(B[0], exact.B[0], 1e-3 * std::hypot(exact.B[0], exact.B[1]));
  EXPECT_NEAR(B[1], exact.B[1], 1e-3 * std::hypot(exact.B[0], exact.B[1]));
}

// The node values are reproduced (the spline interpolates), and A is O(h⁴).
TEST(PolarFieldInterpolator, InterpolatesTheNodeValues)
{
  const MultipoleField f = test_field();
  const PolarGrid g = grid_for(f, 8, 64);
  PolarFieldInterpolator interp(g);
  for (int i = 0; i < g.n_r; i += 3)
    for (int j = 0; j < g.n_theta; j += 7)
    {
      const double r = g.r(i), th = g.theta(j);
      EXPECT_NEAR(interp.vector_potential({r * std::cos(th), r * std::sin(th), 0}), g.at(i, j),
                  1e-12 * std::abs(g.at(i, j)) + 1e-18);
    }
}

TEST(PolarFieldInterpolator, RejectsMalformedGrids)
{
  PolarGrid g = grid_for(test_field(), 8, 64);
  g.A_z[10] = std::nan("");
  EXPECT_THROW(PolarFieldInterpolator{g}, FieldGridError);
  g = grid_for(test_field(), 2, 64); // 3 radial nodes: too few for the not-a-knot spline
  EXPECT_THROW(PolarFieldInterpolator{g}, FieldGridError);
}
