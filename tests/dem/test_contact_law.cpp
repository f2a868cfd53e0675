// Unit tests of the contact sub-models and the material-to-coefficient rules.
#include "dem/contact_law.h"
#include "dem/contact_parameters.h"

#include <gtest/gtest.h>

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
  // The calibrated inverse reproduces e; the ln e form does not (it is exact only for Hooke).
  for (double target : {0.1, 0.5, 0.9})
    EXPECT_NEAR(hertz_restitution(hertz_alpha_for_restitution(target)), target, 1e-6);
  // Kawamoto's α = 0.6 as a restitution coefficient under Hertz.
  std::printf("Kawamoto damping alpha = 0.6 gives e = %.4f with Hertz; ln_e(0.5) gives e = %.4f\n",
              hertz_restitution(0.6), hertz_restitution(ln_e_alpha_normal(0.5)));
  EXPECT_LT(hertz_restitution(0.6), 1.0);
  EXPECT_GT(hertz_restitution(ln_e_alpha_normal(0.5)), 0.5); // the known ln e bias with Hertz
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
