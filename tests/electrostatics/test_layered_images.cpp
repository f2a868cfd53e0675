// The images of a charge in a grounded conductor under a dielectric layer
// (electrostatics/layered_images.h) against an independent evaluation: the Hankel-transform
// integral of the layered medium's reflection coefficient R(k), and both limits (L → 0: the
// grounded conductor, F = q²/(16πε0h²); L → ∞: the dielectric half-space, −β times that).
#include "electrostatics/coulomb_constants.h"
#include "electrostatics/layered_images.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace magbrush::electrostatics;

namespace {

// R(k) of the layer (εr, L) on a grounded substrate, seen from the air, from the boundary
// conditions directly (continuity of φ and of ε ∂φ/∂z at the surface, φ = 0 at −L).
double reflection(double k, double eps_r, double L)
{
  const double coth = 1.0 / std::tanh(k * L);
  return (1.0 - eps_r * coth) / (1.0 + eps_r * coth);
}

// Composite 8-point Gauss–Legendre of f over [a, b] in `panels` panels.
template <class F> double integrate(F f, double a, double b, int panels)
{
  static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                              0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static const double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                              0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  double sum = 0.0;
  const double step = (b - a) / panels;
  for (int p = 0; p < panels; ++p)
    for (int i = 0; i < 8; ++i)
      sum += 0.5 * step * w[i] * f(a + step * (p + 0.5) + 0.5 * step * x[i]);
  return sum;
}

// The normal force on the charge from the layered medium, in units of q²/(4πε0):
// E_z = ∫ k R(k) e^(−2kh) dk (from φ_image = ∫ J0(kρ) R e^(−k(z+h)) dk at ρ = 0, z = h).
double hankel_self_force(double h, double eps_r, double L)
{
  // u = 2kh: ∫ (u/2h) R(u/2h) e^(−u) du/(2h) over u ∈ (0, 60].
  return integrate([&](double u) { return u / (4.0 * h * h) * reflection(u / (2.0 * h), eps_r, L) * std::exp(-u); },
                   1e-12, 60.0, 400);
}

// The image potential at (ρ, z) of a unit charge at height h: ∫ J0(kρ) R(k) e^(−k(z+h)) dk.
double hankel_potential(double h, double rho, double z, double eps_r, double L)
{
  const double s = z + h;
  return integrate([&](double u) { return std::cyl_bessel_j(0.0, u / s * rho) * reflection(u / s, eps_r, L) * std::exp(-u) / s; },
                   1e-12, 60.0, 2000);
}

} // namespace

TEST(LayeredImages, GroundedConductorGivesTheClassicalImageForce)
{
  // F = q²/(16πε0h²) towards the plane; and a vanishing layer tends to it.
  const double q = 1e-14, h = 5e-6;
  const double F = coulomb_constant * q * q * LayeredImages(3.0, 0.0).self_force(h);
  const double exact = -q * q / (16.0 * pi * vacuum_permittivity * h * h);
  EXPECT_NEAR(F / exact, 1.0, 1e-12);
  const double thin = LayeredImages(3.0, 1e-6 * h).self_force(h) / LayeredImages(3.0, 0.0).self_force(h);
  std::printf("layer L = 1e-6 h: force / conductor = %.8f\n", thin);
  EXPECT_NEAR(thin, 1.0, 1e-4);
}

TEST(LayeredImages, ThickLayerTendsToTheDielectricHalfSpace)
{
  const double h = 5e-6, eps_r = 3.0, beta = 0.5;
  const double thick = LayeredImages(eps_r, 1e4 * h).self_force(h);
  std::printf("layer L = 1e4 h: force / (−β/(4h²)) = %.8f\n", thick / (-beta / (4.0 * h * h)));
  EXPECT_NEAR(thick / (-beta / (4.0 * h * h)), 1.0, 1e-4);
}

TEST(LayeredImages, SeriesMatchesHankelIntegral)
{
  // Self force and the potential of the images off axis, over layers from thin to thick.
  double worst_force = 0.0, worst_phi = 0.0;
  for (double eps_r : {1.0, 3.0, 10.0})
    for (double ratio : {0.05, 0.5, 2.0, 20.0}) // L / h
    {
      const double h = 4e-6, L = ratio * h;
      const LayeredImages images(eps_r, L);
      const double series = images.self_force(h), hankel = hankel_self_force(h, eps_r, L);
      worst_force = std::max(worst_force, std::abs(series / hankel - 1.0));
      for (double rho : {0.0, 3e-6, 20e-6})
      {
        const double z = 6e-6;
        const double a = images.image_potential(h, rho, z), b = hankel_potential(h, rho, z, eps_r, L);
        worst_phi = std::max(worst_phi, std::abs(a / b - 1.0));
      }
    }
  std::printf("image series vs Hankel integral: force %.2e, potential %.2e (worst relative)\n", worst_force, worst_phi);
  EXPECT_LT(worst_force, 1e-8);
  EXPECT_LT(worst_phi, 1e-6);
}

TEST(LayeredImages, PairImagesKeepChargeAndDipoleAndApproachTheSeries)
{
  // The lumped pair images: total charge −q, dipole moment 2q(h + L/εr) exactly, and the
  // potential they make at another charge's place close to the full series' (measured, εr = 3,
  // L = 20 µm, h = 4 µm, 10–100 µm away: 3.4e-2, 4.1e-3, 2.0e-4, 3.3e-6 with 1, 2, 4, 8 terms).
  const double h = 4e-6, L = 20e-6, eps_r = 3.0;
  const LayeredImages images(eps_r, L);
  std::vector<double> c, d;
  for (int terms : {1, 2, 4, 8})
  {
    images.pair_images(h, terms, c, d);
    double total = 0.0, dipole = 1.0 * h;
    for (std::size_t k = 0; k < c.size(); ++k)
    {
      total += c[k];
      dipole += c[k] * -d[k];
    }
    EXPECT_NEAR(total, -1.0, 1e-14);
    EXPECT_NEAR(dipole / (2.0 * (h + L / eps_r)), 1.0, 1e-12);
    double worst = 0.0;
    for (double rho : {10e-6, 30e-6, 100e-6})
    {
      double phi = 0.0;
      for (std::size_t k = 0; k < c.size(); ++k)
        phi += c[k] / std::sqrt(rho * rho + (h + d[k]) * (h + d[k]));
      worst = std::max(worst, std::abs(phi / images.image_potential(h, rho, h) - 1.0));
    }
    std::printf("pair images, %d explicit terms: potential at 10–100 µm vs the full series %.2e\n", terms, worst);
    if (terms == 2)
    {
      EXPECT_LT(worst, 1e-2);
    }
    if (terms == 8)
    {
      EXPECT_LT(worst, 1e-5);
    }
  }
}
