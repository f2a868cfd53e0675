// The exact two-sphere force (multipole series): two independent force evaluations agree,
// the known figures at contact are reproduced, and the far field tends to the dipole forms.
#include "magnetics/dipole_physics.h"
#include "magnetics/two_sphere_exact.h"
#include "magnetics/two_sphere_table.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace magbrush::magnetics;

namespace {
double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }
} // namespace

// Energy derivative (co-energy, dS/dd from the differentiated linear system) against the
// Maxwell stress integrated around sphere 2: the same truncated solution, two routes.
TEST(TwoSphereExact, EnergyAndMaxwellStressAgree)
{
  for (double mu : {1.5, 3.9, 20.0})
    for (double D : {2.0, 2.05, 2.2, 3.0, 4.0})
    {
      if (mu == 20.0 && D == 2.0)
        continue; // ~1000 orders at contact: slow, and covered at μr 3.9
      const TwoSphereGeometry g{1.0, 1.0, mu, mu, D};
      const TwoSphereForce e = two_sphere_force(g, 1e-10);
      const TwoSphereForce s = two_sphere_force_stress(g, e.orders);
      SCOPED_TRACE("mu = " + std::to_string(mu) + ", D = " + std::to_string(D));
      EXPECT_LT(rel(s.parallel, e.parallel), 2e-7);
      EXPECT_LT(rel(s.perpendicular, e.perpendicular), 2e-7);
      EXPECT_LT(rel(s.transverse, e.transverse), 2e-7);
    }
}

// The stress integral does not depend on the enclosing sphere (the truncated field is
// harmonic in the gap): a check of the re-expanded field itself.
TEST(TwoSphereExact, StressIndependentOfSurface)
{
  const TwoSphereGeometry g{1.0, 0.7, 3.9, 8.0, 2.6};
  const TwoSphereForce s1 = two_sphere_force_stress(g, 60, 0.7);
  const TwoSphereForce s2 = two_sphere_force_stress(g, 60, 1.2);
  EXPECT_LT(rel(s2.parallel, s1.parallel), 1e-9);
  EXPECT_LT(rel(s2.perpendicular, s1.perpendicular), 1e-9);
  EXPECT_LT(rel(s2.transverse, s1.transverse), 1e-9);
}

// Unequal spheres: the force on sphere 2 equals the force on sphere 1 reversed, so swapping
// the spheres leaves the coefficients unchanged (tests the asymmetric re-expansion signs);
// energy and stress agree too.
TEST(TwoSphereExact, UnequalSpheresSwapSymmetry)
{
  const TwoSphereGeometry g{1.0, 0.6, 3.9, 12.0, 1.75};
  const TwoSphereGeometry h{0.6, 1.0, 12.0, 3.9, 1.75};
  const TwoSphereForce a = two_sphere_force(g, 1e-11), b = two_sphere_force(h, 1e-11);
  EXPECT_LT(rel(b.parallel, a.parallel), 1e-8);
  EXPECT_LT(rel(b.perpendicular, a.perpendicular), 1e-8);
  EXPECT_LT(rel(b.transverse, a.transverse), 1e-8);
  const TwoSphereForce s = two_sphere_force_stress(g, a.orders);
  EXPECT_LT(rel(s.parallel, a.parallel), 1e-7);
  EXPECT_LT(rel(s.transverse, a.transverse), 1e-7);
}

// The classic figures: touching spheres at μr = 3.9, field along the axis, exact/point-dipole ≈ 2.6 and
// mutual-dipole/point-dipole ≈ 1.3. The series gives 2.63221 (converged to 1e-11, see above);
// the 2.6322 quoted in the README is asserted to its last digit.
TEST(TwoSphereExact, TouchingFiguresAtMu3_9)
{
  const double mu = 3.9, beta = clausius_mossotti(mu);
  const TwoSphereForce ex = two_sphere_force({1.0, 1.0, mu, mu, 2.0}, 1e-11);
  const TwoSphereForce pd = point_dipole_pair_force(1.0, beta, 2.0);
  const TwoSphereForce md = mutual_dipole_pair_force(1.0, beta, 2.0);
  const double ratio = ex.parallel / pd.parallel;
  std::printf("touching, mu 3.9: exact/pd = %.5f, md/pd = %.5f (orders %d)\n", ratio,
              md.parallel / pd.parallel, ex.orders);
  EXPECT_NEAR(ratio, 2.6322, 5e-5);
  EXPECT_NEAR(md.parallel / pd.parallel, 1.0 / std::pow(1.0 - 2.0 * beta / 8.0, 2), 1e-14);
  EXPECT_NEAR(md.parallel / pd.parallel, 1.3, 0.01);
}

// Far apart the exact force tends to the mutual-dipole force (the multipoles beyond the
// dipole fall off faster); the relative gap shrinks roughly like D^-3 or faster.
TEST(TwoSphereExact, FarFieldTendsToDipoles)
{
  const double mu = 3.9, beta = clausius_mossotti(mu);
  double previous = 1.0;
  for (double D : {4.0, 8.0, 16.0})
  {
    const TwoSphereForce ex = two_sphere_force({1.0, 1.0, mu, mu, D}, 1e-12);
    const TwoSphereForce md = mutual_dipole_pair_force(1.0, beta, D);
    const double gap = std::max({rel(ex.parallel, md.parallel), rel(ex.perpendicular, md.perpendicular),
                                 rel(ex.transverse, md.transverse)});
    std::printf("D = %4.1f: max |exact - mutual|/|mutual| = %.3e\n", D, gap);
    EXPECT_LT(gap, previous / 6.0);
    previous = gap;
  }
  EXPECT_LT(previous, 1e-3);
  // Unequal spheres far apart: point dipoles p = 4π β a³ H0 each, F∥ = −24π β1 β2 a1³ a2³/d⁴.
  const double b1 = clausius_mossotti(3.9), b2 = clausius_mossotti(10.0), d = 40.0;
  const TwoSphereForce u = two_sphere_force({1.0, 0.5, 3.9, 10.0, d}, 1e-12);
  EXPECT_LT(rel(u.parallel, -24.0 * pi * b1 * b2 * 0.125 / std::pow(d, 4)), 1e-3);
}

// The tabulated correction interpolates the series between its nodes.
TEST(TwoSphereTable, InterpolationMatchesSeries)
{
  const double mu = 3.9, beta = clausius_mossotti(mu);
  const TwoSphereTable table(beta, 5.0);
  double worst = 0.0;
  for (double D : {2.0, 2.013, 2.1, 2.2, 2.37, 3.0, 3.55, 4.0, 4.8})
  {
    const TwoSphereForce ex = two_sphere_force({1.0, 1.0, mu, mu, D}, 1e-12);
    const TwoSphereForce t = table.exact(D);
    worst = std::max({worst, rel(t.parallel, ex.parallel), rel(t.perpendicular, ex.perpendicular),
                      rel(t.transverse, ex.transverse)});
  }
  std::printf("table (96 nodes in sqrt(D-2)): worst relative error %.2e\n", worst);
  EXPECT_LT(worst, 1.5e-5); // measured 1.09e-5
}
