// DEM wall primitives from the case: rotation senses and the nip slip speed (Kawamoto's
// prototype), blade prisms, plane-wall paths.
#include "geometry/wall_primitives.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace magbrush;

namespace {
Case kawamoto_nip()
{
  Case c;
  Sleeve s;
  s.radius = 12.5e-3; // 25 mm sleeve at 219 rpm, counter-clockwise
  s.rpm = 219;
  c.sleeve = s;
  c.drum.present = true;
  c.drum.radius = 50e-3; // 100 mm drum at 29 rpm, clockwise: the surfaces co-move in the nip
  c.drum.rpm = -29;
  c.drum.gap = 0.4e-3;
  c.drum.angle = 0.0;
  return c;
}
} // namespace

TEST(Walls, KawamotoNipSlipSpeed)
{
  const WallSet w = build_wall_primitives(kawamoto_nip());
  ASSERT_EQ(w.cylinders.size(), 2u);
  const CylinderWall &sleeve = *w.cylinder("sleeve"), &drum = *w.cylinder("drum");
  EXPECT_GT(sleeve.omega, 0.0);
  EXPECT_LT(drum.omega, 0.0);
  EXPECT_NEAR(drum.center[0], 12.5e-3 + 0.4e-3 + 50e-3, 1e-15);
  EXPECT_NEAR(drum.center[1], 0.0, 1e-15);
  // Both nip surfaces move along +y.
  const Vec2 vs = sleeve.surface_velocity({12.5e-3, 0.0}), vd = drum.surface_velocity({12.9e-3, 0.0});
  EXPECT_NEAR(vs[1], M_PI * 0.025 * 219 / 60, 1e-12);
  EXPECT_NEAR(vd[1], M_PI * 0.100 * 29 / 60, 1e-12);
  // Kawamoto: relative surface speed 0.135 m/s.
  const double exact = M_PI * 0.025 * 219 / 60 - M_PI * 0.100 * 29 / 60;
  EXPECT_NEAR(nip_relative_surface_speed(w), exact, 1e-12);
  EXPECT_NEAR(nip_relative_surface_speed(w), 0.135, 0.001);
}

TEST(Walls, NipSpeedDoesNotDependOnTheDrumDirection)
{
  Case c = kawamoto_nip();
  const double reference = nip_relative_surface_speed(build_wall_primitives(c));
  c.drum.angle = 2.0;
  EXPECT_NEAR(nip_relative_surface_speed(build_wall_primitives(c)), reference, 1e-12);
  c.drum.present = false;
  EXPECT_THROW(nip_relative_surface_speed(build_wall_primitives(c)), std::invalid_argument);
}

TEST(Walls, BladePrismsAreCounterClockwiseAndChecked)
{
  Case c = kawamoto_nip();
  BladeOrGuide b;
  b.name = "doctor";
  b.polygon = {{0, -13e-3}, {0, -20e-3}, {1e-3, -20e-3}, {1e-3, -13e-3}}; // clockwise
  c.blades.push_back(b);
  const WallSet w = build_wall_primitives(c);
  ASSERT_EQ(w.prisms.size(), 1u);
  EXPECT_NEAR(polygon_signed_area(w.prisms[0].polygon), 7e-6, 1e-18);
  c.blades[0].polygon = {{0, -13e-3}, {1e-3, -20e-3}, {0, -20e-3}, {1e-3, -13e-3}}; // bow tie
  EXPECT_THROW(build_wall_primitives(c), std::invalid_argument);
  c.blades[0].polygon = {{0, -13e-3}, {0, -20e-3}};
  EXPECT_THROW(build_wall_primitives(c), std::invalid_argument);
}

TEST(Walls, PlanePathDisplacementAndVelocity)
{
  Case c;
  PlaneWall p;
  p.name = "plate";
  p.point = {0, 0, 2e-3};
  p.normal = {0, 0, -1};
  // Down 1 mm in 1 ms, then sideways 1.5 mm in 1 ms.
  p.path = {{0.0, {0, 0, 0}}, {1e-3, {0, 0, -1e-3}}, {2e-3, {1.5e-3, 0, -1e-3}}};
  c.planes.push_back(p);
  const WallSet w = build_wall_primitives(c);
  ASSERT_EQ(w.planes.size(), 1u);
  const PlaneWallPrimitive &plate = w.planes[0];
  const Vec3 d1 = plate.displacement(0.25e-3), d2 = plate.displacement(1.5e-3), d3 = plate.displacement(5e-3);
  EXPECT_NEAR(d1[2], -0.25e-3, 1e-15);
  EXPECT_NEAR(d2[0], 0.75e-3, 1e-15);
  EXPECT_NEAR(d2[2], -1e-3, 1e-15);
  EXPECT_NEAR(d3[0], 1.5e-3, 1e-15); // holds its end position
  const Vec3 v1 = plate.velocity(0.5e-3), v2 = plate.velocity(1.5e-3), v3 = plate.velocity(3e-3);
  EXPECT_NEAR(v1[2], -1.0, 1e-12);
  EXPECT_NEAR(v2[0], 1.5, 1e-12);
  EXPECT_NEAR(v2[2], 0.0, 1e-12);
  EXPECT_EQ(v3, (Vec3{0, 0, 0}));
  EXPECT_EQ(plate.velocity(-1.0), (Vec3{0, 0, 0}));
}

TEST(Walls, PolygonHelpers)
{
  const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(point_in_polygon({0.5, 0.5}, square));
  EXPECT_FALSE(point_in_polygon({1.5, 0.5}, square));
  EXPECT_NEAR(distance_to_polygon_boundary({2, 0.5}, square), 1.0, 1e-15);
  EXPECT_NEAR(distance_to_polygon_boundary({2, 2}, square), std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(polygons_overlap(square, {{0.5, 0.5}, {2, 0.5}, {2, 2}}));
  EXPECT_TRUE(polygons_overlap(square, {{0.2, 0.2}, {0.4, 0.2}, {0.4, 0.4}})); // nested
  EXPECT_FALSE(polygons_overlap(square, {{2, 2}, {3, 2}, {3, 3}}));
}

TEST(Walls, SpinUpTimesReachTheCylinders)
{
  // The case's sleeve.spin_up_time / drum.spin_up_time become the cylinders' linear ramps
  // (the DEM test DemWalls.CylinderSpinsUpLinearly checks the ramp itself).
  Case c = kawamoto_nip();
  c.sleeve->spin_up_time = 1e-3;
  c.drum.spin_up_time = 2e-3;
  const WallSet w = build_wall_primitives(c);
  EXPECT_EQ(w.cylinder("sleeve")->spin_up_time, 1e-3);
  EXPECT_EQ(w.cylinder("drum")->spin_up_time, 2e-3);
  EXPECT_EQ(build_wall_primitives(kawamoto_nip()).cylinder("sleeve")->spin_up_time, 0.0);
}
