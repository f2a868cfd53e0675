#include "tests/geometry/mesh_test_cases.h"

#include "tests/test_temp_dir.h"

#include <cmath>
#include <filesystem>
#include <unistd.h>

namespace magbrush::testing {

Case coarse_roller_case()
{
  Case c;
  c.name = "geometry_test_roller";
  Roller r;
  r.shaft_radius = 3e-3;
  r.shaft_mu_r = 1000;
  r.magnet_radius = 9.3e-3;
  for (int k = 0; k < 5; ++k)
    r.poles.push_back({"P" + std::to_string(k), 2 * M_PI * k / 5, (k % 2 ? 1 : -1) * 2e5, 10.0});
  c.roller = r;
  Sleeve s;
  s.radius = 10e-3;
  s.thickness = 0.5e-3;
  s.rpm = 400;
  c.sleeve = s;
  // A soft-magnetic doctor blade below the roller: a 1.5 mm × 6 mm plate, 0.5 mm gap,
  // given clockwise on purpose (the geometry stage must accept either orientation).
  BladeOrGuide blade;
  blade.name = "doctor";
  blade.mu_r = 50;
  blade.is_doctor_blade = true;
  blade.gap = 0.5e-3;
  blade.polygon = {Vec2{{-0.75e-3, -10.5e-3}}, Vec2{{-0.75e-3, -16.5e-3}}, Vec2{{0.75e-3, -16.5e-3}}, Vec2{{0.75e-3, -10.5e-3}}};
  c.blades.push_back(blade);
  BladeOrGuide guide;
  guide.name = "guide";
  guide.polygon = {Vec2{{-6.183e-3, -9.709e-3}}, Vec2{{-8.433e-3, -13.606e-3}}, Vec2{{-7.567e-3, -14.106e-3}}, Vec2{{-5.317e-3, -10.209e-3}}};
  c.blades.push_back(guide);
  c.field.mesh_size_sleeve = 0.4e-3;
  c.field.mesh_size_far = 3e-3;
  return c;
}

Case coarse_nip_case(double pc_thickness)
{
  Case c;
  c.name = "geometry_test_nip";
  Sleeve s;
  s.radius = 10e-3;
  s.thickness = 0.5e-3;
  s.rpm = 400;
  c.sleeve = s;
  c.drum.present = true;
  c.drum.radius = 15e-3;
  c.drum.rpm = -170;
  c.drum.gap = 0.35e-3;
  c.drum.angle = 30.0 * M_PI / 180.0; // off-axis on purpose
  c.drum.pc_thickness = pc_thickness;
  c.field.mesh_size_gap = 50e-6;
  c.field.mesh_size_far = 3e-3;
  return c;
}

std::string scratch_dir(const std::string &name)
{
  // One directory per process: ctest runs the test cases of one executable in parallel.
  return magbrush::testing::test_temp_dir("mesh_" + name).string();
}

} // namespace magbrush::testing
