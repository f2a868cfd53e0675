// Unit tests of the contact sub-models and the material-to-coefficient rules.
#include "dem/contact_law.h"
#include "dem/contact_parameters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace magbrush;
using namespace magbrush::dem;

TEST(ContactLaw, PolygonRuleForRollingFriction)
{
  EXPECT_NEAR(rolling_friction_from_polygon(12), std::sin(M_PI / 12), 1e-15);
  EXPECT_NEAR(rolling_friction_from_polygon(12), 0.258819, 1e-6);
  EXPECT_NEAR(rolling_friction_from_polygon(4), std::sqrt(0.5), 1e-15); // a square tips at 45°
  EXPECT_THROW(rolling_friction_from_polygon(2), std::invalid_argument);
}

TEST(ContactLaw, RestitutionFormsAndTheHertzOde)
{
  EXPECT_EQ(ln_e_alpha_normal(1.0), 0.0);
  EXPECT_NEAR(hertz_restitution(0.0), 1.0, 1e-6);
  // ln e form: β = ln e / √(ln² e + π²), α_n = √5 |β|.
  const double e = 0.5, b = std::log(e) / std::sqrt(std::log(e) * std::log(e) + M_PI * M_PI);
  EXPECT_NEAR(ln_e_alpha_normal(e), std::sqrt(5.0) * std::abs(b), 1e-15);
  // The calibrated inverse is checked against results that do not come from the same ODE
  // solver: the weak-damping limit and an independent integration (below).
  // Kawamoto's α = 0.6 as a restitution coefficient under Hertz.
  std::printf("Kawamoto damping alpha = 0.6 gives e = %.4f with Hertz; ln_e(0.5) gives e = %.4f\n",
              hertz_restitution(0.6), hertz_restitution(ln_e_alpha_normal(0.5)));
  EXPECT_LT(hertz_restitution(0.6), 1.0);
  EXPECT_GT(hertz_restitution(ln_e_alpha_normal(0.5)), 0.5); // the known ln e bias with Hertz
}

// Weak damping, in closed form: with E = ξ'²/2 + (2/5) ξ^{5/2} the dashpot removes
// ΔE = α ∮ ξ^{1/4} ξ'² dt = 2α ∫₀^{ξm} ξ^{1/4} √(1 − (4/5) ξ^{5/2}) dξ = α π √5 / 5 on the elastic
// path (u = (4/5) ξ^{5/2} turns the integral into (2/5)(5/4)^{1/2} B(1/2, 3/2)), so
// 1 − e = ΔE + O(α²) = (π/√5) α + O(α²). (1 − e)/α at two small α, extrapolated linearly to
// α = 0, must give π/√5 (the O(α²) coefficient is about −1.4).
TEST(ContactLaw, HertzRestitutionHasTheWeakDampingLimit)
{
  const double slope = M_PI / std::sqrt(5.0);
  const double a1 = 1e-4, a2 = 1e-3;
  const double s1 = (1.0 - hertz_restitution(a1)) / a1, s2 = (1.0 - hertz_restitution(a2)) / a2;
  const double s0 = s1 + (s1 - s2) * a1 / (a2 - a1);
  std::printf("(1 - e)/alpha = %.6f at %.0e, %.6f at %.0e; extrapolated to 0: %.6f (pi/sqrt5 = %.6f)\n", s1, a1,
              s2, a2, s0, slope);
  EXPECT_NEAR(s0, slope, 5e-5);
  EXPECT_NEAR(s1, slope, 3.0 * a1); // and the slope at α = 1e-4 is already within the O(α) term
  // The calibrated inverse has the same limit.
  EXPECT_NEAR(hertz_alpha_for_restitution(1.0 - 1e-4) * slope / 1e-4, 1.0, 1e-3);
}

// The α that hertz_exact picks for e, put into an integration of the contact written here
// (velocity Verlet with a fixed small step, exit where the repulsive force vanishes), gives e
// back: the inverse is checked by another solver than the one it bisects.
TEST(ContactLaw, HertzExactDampingGivesTheRequestedRestitution)
{
  for (double target : {0.1, 0.5, 0.9})
  {
    const double alpha = hertz_alpha_for_restitution(target);
    const double h = 2e-5;
    double xi = 0.0, v = 1.0;
    auto accel = [alpha](double x, double u) {
      const double s = std::max(x, 0.0);
      return -(s * std::sqrt(s) + alpha * std::sqrt(std::sqrt(s)) * u);
    };
    double a = accel(xi, v);
    for (long k = 0; k < 10000000; ++k)
    {
      const double x_new = xi + h * v + 0.5 * h * h * a;
      // Velocity half step, then the implicit velocity-dependent force by two fixed-point passes.
      double v_new = v + h * a;
      for (int it = 0; it < 2; ++it)
        v_new = v + 0.5 * h * (a + accel(x_new, v_new));
      xi = x_new;
      v = v_new;
      a = accel(xi, v);
      if (k > 10 && v < 0.0 && (xi <= 0.0 || a >= 0.0))
        break;
    }
    std::printf("e requested %.2f: alpha %.6f, independent integration e = %.6f\n", target, alpha, -v);
    EXPECT_NEAR(-v, target, 2e-5) << "e = " << target; // measured within 4e-6
  }
}

namespace {
ContactKinematics head_on(double delta, double v_approach, double v_tangential)
{
  ContactKinematics k;
  k.n = {1, 0, 0};
  k.overlap = delta;
  k.lever_i = k.lever_j = 1e-3 - delta / 2;
  k.v_rel = {v_approach, v_tangential, 0};
  k.R_star = 0.5e-3;
  k.m_star = 1e-6;
  k.radius_i = k.radius_j = 1e-3;
  k.inv_inertia_i = k.inv_inertia_j = 1.0 / (0.4 * 2e-6 * 1e-6);
  return k;
}
} // namespace

TEST(ContactLaw, HertzNormalForceAndCoulombLimit)
{
  ContactCoefficients c;
  c.effective_modulus = 1e9;
  c.effective_shear = 4e8;
  c.friction = 0.3;
  const double delta = 1e-6;
  Vector3 xi{};
  const auto o = evaluate_contact(c, head_on(delta, 0.0, 0.0), xi, 1e-8);
  const double fn = 4.0 / 3.0 * 1e9 * std::sqrt(0.5e-3) * std::pow(delta, 1.5);
  EXPECT_NEAR(o.force_i.x, -fn, 1e-12 * fn); // pushes i away from j
  EXPECT_NEAR(o.normal_force, fn, 1e-12 * fn);
  // Fast sliding: the tangential force sits on the Coulomb cone, opposite to the sliding.
  Vector3 xi2{};
  const auto s = evaluate_contact(c, head_on(delta, 0.0, 1.0), xi2, 1e-3);
  EXPECT_NEAR(s.force_i.y, -0.3 * fn, 1e-12 * fn);
  // The spring was reset to carry exactly the Coulomb force.
  const double k_t = 8.0 * 4e8 * std::sqrt(0.5e-3 * delta);
  EXPECT_NEAR(-k_t * xi2.y, -0.3 * fn, 1e-9 * fn);
  // The torques: lever × force on both bodies, same sense (they spin the same way).
  EXPECT_NEAR(s.torque_i.z, s.torque_j.z, 1e-15);
}

TEST(ContactLaw, DashpotNeverPulls)
{
  ContactCoefficients c;
  c.effective_modulus = 1e9;
  c.effective_shear = 4e8;
  c.damping_normal = 5.0;
  Vector3 xi{};
  const auto o = evaluate_contact(c, head_on(1e-9, -10.0, 0.0), xi, 1e-8); // fast separation
  EXPECT_EQ(o.normal_force, 0.0);
  EXPECT_EQ(o.force_i.x, 0.0);
}

TEST(ContactLaw, MixingRules)
{
  Material a, b;
  a.name = "a";
  a.youngs_modulus = 1e9;
  a.poisson_ratio = 0.35;
  a.friction = 0.45;
  a.polygon_angles = 12;
  a.damping = 0.6;
  b.name = "wall";
  b.youngs_modulus = 5e10;
  b.poisson_ratio = 0.3;
  b.friction = 0.35;
  const auto c = mix_materials(a, b, true, "ln_e");
  EXPECT_NEAR(c.effective_modulus, 1.0 / ((1 - 0.35 * 0.35) / 1e9 + (1 - 0.09) / 5e10), 1e-3);
  const double Ga = 1e9 / 2.7, Gb = 5e10 / 2.6;
  EXPECT_NEAR(c.effective_shear, 1.0 / ((2 - 0.35) / Ga + (2 - 0.3) / Gb), 1e-3);
  EXPECT_EQ(c.friction, 0.35); // Kawamoto: particle–wall friction is the wall's
  EXPECT_NEAR(c.rolling_friction, std::sin(M_PI / 12), 1e-15);
  EXPECT_EQ(c.damping_normal, 0.6);
  a.youngs_modulus = 0;
  EXPECT_THROW(mix_materials(a, b, true, "ln_e"), std::invalid_argument);
}
