// Chung & Ooi (2011) DEM impact benchmarks, tests 1–4, against Hertz theory and the rigid-body
// theory of oblique impact. Parameters and reference values (copied from the project's data
// sheet "chung_ooi_2011_tests_1-4.md"; recomputed there from the closed forms):
//   test 1  two spheres R = 10 mm, ±10 m/s: glass 48 GPa/0.20/2800 → δmax 274.1 µm, Fmax
//           10.70 kN, t_c 40.3 µs; limestone 20 GPa/0.25/2500 → 368.3 µm, 7.11 kN, 54.2 µs
//   test 2  sphere R = 0.1 m on a rigid plane at 0.2 m/s: Al 70 GPa/0.30/2699 → 49.7 µm,
//           11.37 kN, 732 µs; Mg 40 GPa/0.35/1800 → 52.1 µm, 7.23 kN, 767 µs
//   test 3  alumina 380 GPa/0.23/4000 (and cast iron 100 GPa/0.25/7000), R = 2.5 mm, 3.9 m/s
//           on a rigid plane, restitution 0…1
//   test 4  alumina sphere on an Al-alloy plate (70 GPa, 0.33), |v| = 3.9 m/s at 0–90° from
//           the normal, μ = 0.092, e = 0.98: gross sliding for tan θ ≥ 3.5 μ (1 + e), where
//           ω' = 2.5 μ (1 + e) V_n / R and v_t'/v_t = 1 − μ (1 + e) / tan θ.
#include "tests/dem/dem_test_scenes.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

struct ImpactResult
{
  double delta_max = 0, force_max = 0, duration = 0;
  Vector3 v_after, w_after, v_before;
};

std::size_t index_of(const ParticleState &s, int id)
{
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.id[i] == id)
      return i;
  return s.size();
}

// Runs until the contact has ended; `overlap` reports the current overlap (< 0 apart).
template <typename Overlap>
ImpactResult run_impact(DemSystem &sys, int watched_id, Overlap &&overlap, long max_steps)
{
  ImpactResult r;
  double prev = overlap(sys), t_in = -1, t_out = -1;
  r.v_before = sys.particles().velocity(index_of(sys.particles(), watched_id));
  for (long k = 0; k < max_steps && t_out < 0; ++k)
  {
    const double t0 = sys.time();
    sys.step();
    const double d = overlap(sys);
    const std::size_t i = index_of(sys.particles(), watched_id);
    const auto &f = sys.forces();
    r.delta_max = std::max(r.delta_max, d);
    if (d > 0)
      r.force_max = std::max(r.force_max, std::sqrt(f.fx[i] * f.fx[i] + f.fy[i] * f.fy[i] + f.fz[i] * f.fz[i]));
    // Contact start and end by linear interpolation of the overlap between steps.
    if (prev <= 0 && d > 0 && t_in < 0)
      t_in = t0 + sys.time_step() * (-prev) / (d - prev);
    if (prev > 0 && d <= 0 && t_in >= 0)
      t_out = t0 + sys.time_step() * prev / (prev - d);
    prev = d;
  }
  EXPECT_GE(t_out, 0.0) << "the contact did not end within " << max_steps << " steps";
  r.duration = t_out - t_in;
  // A few more steps of free flight (no forces) do not change the velocities.
  const std::size_t i = index_of(sys.particles(), watched_id);
  r.v_after = sys.particles().velocity(i);
  r.w_after = sys.particles().angular_velocity(i);
  return r;
}

void expect_relative(double measured, double expected, double tol, const char *what)
{
  EXPECT_NEAR(measured / expected, 1.0, tol) << what << ": measured " << measured << ", expected " << expected;
}

// Test 1: two identical spheres head-on.
ImpactResult two_sphere_impact(const Material &m, double R, double v, double dt_fraction)
{
  Case c = single_species_case(m);
  const double E_star = m.youngs_modulus / (2.0 * (1.0 - m.poisson_ratio * m.poisson_ratio));
  const double mass = m.density * 4.0 / 3.0 * M_PI * R * R * R;
  const HertzImpact h = hertz_impact(0.5 * mass, 0.5 * R, E_star, 2.0 * v);
  c.dem.time_step = h.duration * dt_fraction;
  c.dem.verlet_skin = 0.1;
  DemSystem sys(c);
  sys.particles().add({-R - 1e-9, 0, 0}, R, m.density, 0, 0.0);
  sys.particles().add({R + 1e-9, 0, 0}, R, m.density, 0, 0.0);
  sys.particles().vx = {v, -v};
  sys.initialize();
  auto overlap = [R](const DemSystem &s) {
    const auto &p = s.particles();
    return 2.0 * R - std::abs(p.x[1] - p.x[0]);
  };
  return run_impact(sys, 0, overlap, 100000);
}

// A sphere falling on a plane z = 0 with normal velocity v (and tangential u along x).
ImpactResult sphere_plane_impact(Case c, const Material &m, double R, double v, double u, double dt)
{
  c.dem.time_step = dt;
  c.dem.verlet_skin = 0.1;
  DemSystem sys(c);
  sys.particles().add({0, 0, R + 1e-9}, R, m.density, 0, 0.0);
  sys.particles().vz = {-v};
  sys.particles().vx = {u};
  sys.initialize();
  auto overlap = [R](const DemSystem &s) { return R - s.particles().z[0]; };
  return run_impact(sys, 0, overlap, 2000000);
}

} // namespace

TEST(ChungOoi, Test1TwoSpheresElasticNormalImpact)
{
  struct Row
  {
    const char *name;
    double E, nu, rho, delta, force, tc;
  } rows[] = {{"glass", 48e9, 0.20, 2800, 274.1e-6, 10.70e3, 40.3e-6},
              {"limestone", 20e9, 0.25, 2500, 368.3e-6, 7.11e3, 54.2e-6}};
  std::printf("Chung & Ooi test 1 (two spheres, R = 10 mm, approach 20 m/s):\n"
              "  material    dmax [um] (Hertz)      Fmax [kN] (Hertz)     t_c [us] (Hertz)\n");
  for (const auto &row : rows)
  {
    const Material m = elastic_material(row.name, row.E, row.nu, row.rho);
    const double R = 0.01, v = 10.0;
    const double E_star = row.E / (2.0 * (1.0 - row.nu * row.nu));
    const double mass = row.rho * 4.0 / 3.0 * M_PI * R * R * R;
    const HertzImpact h = hertz_impact(0.5 * mass, 0.5 * R, E_star, 2.0 * v);
    // The closed forms reproduce the published figures (to their 3–4 digits).
    EXPECT_NEAR(h.delta_max / row.delta, 1.0, 2e-3);
    EXPECT_NEAR(h.force_max / row.force, 1.0, 2e-3);
    EXPECT_NEAR(h.duration / row.tc, 1.0, 3e-3);
    const ImpactResult r = two_sphere_impact(m, R, v, 1.0 / 2000.0);
    std::printf("  %-10s %8.2f (%8.2f)   %8.4f (%8.4f)   %8.3f (%8.3f)   rebound %.6f m/s\n", row.name,
                r.delta_max * 1e6, h.delta_max * 1e6, r.force_max * 1e-3, h.force_max * 1e-3, r.duration * 1e6,
                h.duration * 1e6, r.v_after.x);
    expect_relative(r.delta_max, h.delta_max, 1e-4, "max overlap");
    expect_relative(r.force_max, h.force_max, 1e-4, "max force");
    expect_relative(r.duration, h.duration, 1e-4, "contact duration");
    // Elastic: the rebound speed equals the impact speed.
    EXPECT_NEAR(r.v_after.x, -v, 1e-4 * v);
  }
}

TEST(ChungOoi, Test2SpherePlaneElasticNormalImpact)
{
  struct Row
  {
    const char *name;
    double E, nu, rho, delta, force, tc;
  } rows[] = {{"Al alloy", 70e9, 0.30, 2699, 49.7e-6, 11.37e3, 732e-6},
              {"Mg alloy", 40e9, 0.35, 1800, 52.1e-6, 7.23e3, 767e-6}};
  std::printf("Chung & Ooi test 2 (sphere R = 0.1 m on a rigid plane, 0.2 m/s):\n"
              "  material    dmax [um] (Hertz)      Fmax [kN] (Hertz)     t_c [us] (Hertz)\n");
  for (const auto &row : rows)
  {
    const Material m = elastic_material("sphere", row.E, row.nu, row.rho);
    Case c = single_species_case(m);
    add_rigid_plane(c, {0, 0, 0}, {0, 0, 1});
    const double R = 0.1, v = 0.2;
    const double mass = row.rho * 4.0 / 3.0 * M_PI * R * R * R;
    const HertzImpact h = hertz_impact(mass, R, row.E / (1.0 - row.nu * row.nu), v);
    EXPECT_NEAR(h.delta_max / row.delta, 1.0, 2e-3);
    EXPECT_NEAR(h.force_max / row.force, 1.0, 2e-3);
    EXPECT_NEAR(h.duration / row.tc, 1.0, 3e-3);
    const ImpactResult r = sphere_plane_impact(c, m, R, v, 0.0, h.duration / 2000.0);
    std::printf("  %-10s %8.3f (%8.3f)   %8.4f (%8.4f)   %8.2f (%8.2f)\n", row.name, r.delta_max * 1e6,
                h.delta_max * 1e6, r.force_max * 1e-3, h.force_max * 1e-3, r.duration * 1e6, h.duration * 1e6);
    expect_relative(r.delta_max, h.delta_max, 1e-4, "max overlap");
    expect_relative(r.force_max, h.force_max, 1e-4, "max force");
    expect_relative(r.duration, h.duration, 1e-4, "contact duration");
    EXPECT_NEAR(r.v_after.z, v, 1e-4 * v);
  }
}

TEST(ChungOoi, Test3RestitutionAgainstInputDamping)
{
  const double R = 2.5e-3, v = 3.9;
  struct Mat
  {
    const char *name;
    double E, nu, rho;
  } mats[] = {{"alumina", 380e9, 0.23, 4000}, {"cast iron", 100e9, 0.25, 7000}};
  std::printf("Chung & Ooi test 3 (R = 2.5 mm on a rigid plane, 3.9 m/s): restitution\n"
              "  material    e_input   ln_e form: e_measured  e_ODE(alpha)   hertz_exact: e_measured\n");
  for (const auto &mt : mats)
    for (double e : {0.1, 0.3, 0.5, 0.7, 0.9, 0.98})
    {
      double measured[2];
      int k = 0;
      for (const char *model : {"ln_e", "hertz_exact"})
      {
        Material m = elastic_material("sphere", mt.E, mt.nu, mt.rho);
        m.restitution = e;
        Case c = single_species_case(m);
        c.dem.restitution_model = model;
        add_rigid_plane(c, {0, 0, 0}, {0, 0, 1});
        const double mass = mt.rho * 4.0 / 3.0 * M_PI * R * R * R;
        const HertzImpact h = hertz_impact(mass, R, mt.E / (1.0 - mt.nu * mt.nu), v);
        const ImpactResult r = sphere_plane_impact(c, m, R, v, 0.0, h.duration / 2000.0);
        measured[k++] = r.v_after.z / v;
      }
      const double e_ode = hertz_restitution(ln_e_alpha_normal(e));
      std::printf("  %-10s %6.3f     %10.4f          %10.4f      %10.4f\n", mt.name, e, measured[0], e_ode,
                  measured[1]);
      // The DEM reproduces the dashpot's restitution as the independent ODE gives it ...
      EXPECT_NEAR(measured[0] / e_ode, 1.0, 5e-3) << mt.name << " e = " << e;
      // ... and the calibrated form gives exactly the input.
      EXPECT_NEAR(measured[1] / e, 1.0, 5e-3) << mt.name << " e = " << e;
    }
}

TEST(ChungOoi, Test4ObliqueImpact)
{
  const double R = 2.5e-3, speed = 3.9, mu = 0.092, e = 0.98;
  Material sphere = elastic_material("alumina", 380e9, 0.23, 4000);
  sphere.restitution = e;
  const double threshold = std::atan(3.5 * mu * (1.0 + e)) * 180.0 / M_PI;
  EXPECT_NEAR(threshold, 32.5, 0.2);
  std::printf("Chung & Ooi test 4 (alumina on Al plate, 3.9 m/s, mu = 0.092, e = 0.98); gross sliding "
              "above %.2f deg\n  angle   omega' [rad/s] (sliding theory)   v_t'/v_t (sliding theory)   e_n\n",
              threshold);
  for (double deg : {5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0})
  {
    Case c = single_species_case(sphere);
    c.dem.restitution_model = "hertz_exact";
    Material plate = elastic_material("plate", 70e9, 0.33, 2700);
    plate.friction = mu;
    c.materials.push_back(plate);
    PlaneWall p;
    p.name = "plate";
    p.normal = {0, 0, 1};
    p.material = "plate";
    c.planes.push_back(p);
    const double th = deg * M_PI / 180.0;
    const double vn = speed * std::cos(th), vt = speed * std::sin(th);
    const double mass = 4000 * 4.0 / 3.0 * M_PI * R * R * R;
    const double E_star = 1.0 / ((1 - 0.23 * 0.23) / 380e9 + (1 - 0.33 * 0.33) / 70e9);
    const HertzImpact h = hertz_impact(mass, R, E_star, vn);
    const ImpactResult r = sphere_plane_impact(c, sphere, R, vn, vt, h.duration / 2000.0);
    const double w_slide = 2.5 * mu * (1 + e) * vn / R;
    const double et_slide = 1.0 - mu * (1 + e) / std::tan(th);
    // Friction −x at the bottom contact (lever −a ẑ) spins the sphere about +y.
    const double w = r.w_after.y;
    const double et = r.v_after.x / vt;
    std::printf("  %5.1f   %9.2f (%9.2f)          %8.4f (%8.4f)         %.4f\n", deg, w, w_slide, et, et_slide,
                r.v_after.z / vn);
    EXPECT_NEAR(r.v_after.z / vn, e, 5e-3);
    if (deg > threshold + 5.0)
    {
      EXPECT_NEAR(w / w_slide, 1.0, 5e-3) << deg << " deg";
      EXPECT_NEAR(et, et_slide, 5e-3) << deg << " deg";
    }
    else if (deg < threshold - 5.0)
    {
      // Sticking/micro-slip: less spin than gross sliding would give.
      EXPECT_LT(w, w_slide) << deg << " deg";
      EXPECT_GT(w, 0.0) << deg << " deg";
    }
  }
}
