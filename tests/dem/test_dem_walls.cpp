// Wall primitives as the DEM sees them: contact geometry of cylinders (outside and inside),
// planes on a prescribed path and extruded polygons (faces, corners, penetration), and two
// dynamic checks: a particle carried along by a plate sliding sideways (Kawamoto's shear
// step) and a particle resting on a blade face at the Hertz static overlap.
#include "tests/dem/dem_test_scenes.h"
#include "dem/force_terms/gravity.h"

#include "dem/wall_contacts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>
#include <cmath>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

TEST(DemWalls, CylinderOutsideAndInside)
{
  WallSet ws;
  CylinderWall sleeve;
  sleeve.name = "sleeve";
  sleeve.radius = 10e-3;
  sleeve.omega = 20.0;
  sleeve.material = "sleeve";
  ws.cylinders.push_back(sleeve);
  sleeve.name = "drum";
  sleeve.particles_outside = false;
  sleeve.radius = 20e-3;
  ws.cylinders.push_back(sleeve);
  DemWalls walls(ws);
  walls.prepare(0.0, false);
  WallContactGeometry g;
  // Outside the sleeve at angle 90°, 1 µm overlap: the wall is towards the axis (−y).
  ASSERT_TRUE(walls.contact(0, {0, 10e-3 + 49e-6, 0}, 50e-6, g));
  EXPECT_NEAR(g.overlap, 1e-6, 1e-15);
  EXPECT_NEAR(g.n.y, -1.0, 1e-15);
  // Surface velocity ω ẑ × (0, R) = (−ωR, 0).
  EXPECT_NEAR(g.surface_velocity.x, -20.0 * 10e-3, 1e-15);
  EXPECT_NEAR(g.angular_velocity.z, 20.0, 0);
  EXPECT_FALSE(walls.contact(0, {0, 10e-3 + 51e-6, 0}, 50e-6, g));
  // Inside the drum near +x: the wall is outward (+x).
  ASSERT_TRUE(walls.contact(1, {20e-3 - 48e-6, 0, 0}, 50e-6, g));
  EXPECT_NEAR(g.overlap, 2e-6, 1e-15);
  EXPECT_NEAR(g.n.x, 1.0, 1e-15);
  EXPECT_NEAR(g.surface_velocity.y, 20.0 * 20e-3, 1e-15);
  // Frozen (settling): at rest.
  walls.prepare(0.0, true);
  ASSERT_TRUE(walls.contact(1, {20e-3 - 48e-6, 0, 0}, 50e-6, g));
  EXPECT_EQ(g.surface_velocity.y, 0.0);
}

// The wall phase's pre-filter (no square root) never turns away a contact the exact test
// finds: points scattered within a few radii of each cylinder's surface, thousands of them
// within a few ulps of the touching distance, both senses, with and without an adhesion
// range; and it does turn away the particles far from the wall (what it is for).
TEST(DemWalls, CylinderPreFilterNeverMissesAContact)
{
  WallSet ws;
  CylinderWall c;
  c.name = c.material = "sleeve";
  c.center = {1e-3, -2e-3};
  c.radius = 12.5e-3;
  ws.cylinders.push_back(c);
  c.name = c.material = "housing";
  c.particles_outside = false;
  c.radius = 20e-3;
  ws.cylinders.push_back(c);
  DemWalls walls(ws);
  walls.prepare(0.0, false);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), unit(-1.0, 1.0);
  long touching = 0, turned_away = 0;
  for (int k = 0; k < 200000; ++k)
  {
    const std::size_t w = static_cast<std::size_t>(k % 2);
    const double R = w == 0 ? 12.5e-3 : 20e-3, r = 30e-6, range = (k % 3 == 0) ? 0.4e-6 : 0.0;
    // Half the points at the touching distance to within a few ulps, half within 4 radii.
    const double touch = w == 0 ? R + r + range : R - r - range;
    const double d = (k % 4 < 2) ? touch * (1.0 + 4e-16 * unit(rng)) : touch + 4.0 * r * unit(rng);
    const double a = angle(rng);
    const Vector3 p{1e-3 + d * std::cos(a), -2e-3 + d * std::sin(a), 0.0};
    WallContactGeometry g;
    const bool exact = walls.contact(w, p, r, g, range);
    const bool may = walls.may_touch(w, p, r + range);
    touching += exact;
    turned_away += !may;
    ASSERT_TRUE(may || !exact) << "wall " << w << " point " << k;
  }
  EXPECT_GT(touching, 20000);
  EXPECT_GT(turned_away, 20000);
}

TEST(DemWalls, PlaneFollowsItsPath)
{
  WallSet ws;
  PlaneWallPrimitive plate;
  plate.name = "plate";
  plate.point = {0, 0, 1e-3};
  plate.normal = {0, 0, -2}; // normalised by the DEM
  plate.path = {{0.0, {0, 0, 0}}, {1e-3, {0, 0, -0.5e-3}}, {2e-3, {1e-3, 0, -0.5e-3}}};
  ws.planes.push_back(plate);
  DemWalls walls(ws);
  WallContactGeometry g;
  walls.prepare(0.5e-3, false); // half-way down: plane at z = 0.75 mm moving at −0.5 m/s
  EXPECT_FALSE(walls.contact(0, {0, 0, 0.7e-3}, 40e-6, g));
  ASSERT_TRUE(walls.contact(0, {0, 0, 0.72e-3}, 40e-6, g));
  EXPECT_NEAR(g.overlap, 10e-6, 1e-12);
  EXPECT_NEAR(g.n.z, 1.0, 1e-15);
  EXPECT_NEAR(g.surface_velocity.z, -0.5, 1e-12);
  walls.prepare(1.5e-3, false); // sliding sideways at +1 m/s
  ASSERT_TRUE(walls.contact(0, {0, 0, 0.47e-3}, 40e-6, g));
  EXPECT_NEAR(g.surface_velocity.x, 1.0, 1e-12);
  EXPECT_NEAR(g.surface_velocity.z, 0.0, 1e-12);
}

TEST(DemWalls, PrismFacesCornersAndPenetration)
{
  WallSet ws;
  PrismWall blade;
  blade.name = "blade";
  blade.polygon = {{0, 0}, {1e-3, 0}, {1e-3, 1e-3}, {0, 1e-3}};
  ws.prisms.push_back(blade);
  DemWalls walls(ws);
  walls.prepare(0.0, false);
  WallContactGeometry g;
  // Face below the square.
  ASSERT_TRUE(walls.contact(0, {0.5e-3, -45e-6, 0.3}, 50e-6, g));
  EXPECT_NEAR(g.overlap, 5e-6, 1e-15);
  EXPECT_NEAR(g.n.y, 1.0, 1e-12);
  // Corner (1 mm, 1 mm) seen along the diagonal.
  const double s = 40e-6 / std::sqrt(2.0);
  ASSERT_TRUE(walls.contact(0, {1e-3 + s, 1e-3 + s, 0}, 50e-6, g));
  EXPECT_NEAR(g.overlap, 10e-6, 1e-12);
  EXPECT_NEAR(g.n.x, -std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(g.n.y, -std::sqrt(0.5), 1e-12);
  // Far away: rejected by the bounding box.
  EXPECT_FALSE(walls.contact(0, {5e-3, 5e-3, 0}, 50e-6, g));
  // Centre inside the blade (deep penetration): pushed out through the nearest face (x = 0).
  ASSERT_TRUE(walls.contact(0, {10e-6, 0.5e-3, 0}, 50e-6, g));
  EXPECT_NEAR(g.overlap, 60e-6, 1e-12);
  EXPECT_NEAR(g.n.x, 1.0, 1e-12); // wall towards +x: the force pushes the particle to −x
  EXPECT_NEAR(walls.distance(0, {10e-6, 0.5e-3, 0}, 0.0), -10e-6, 1e-15);
}

TEST(DemWalls, SlidingPlateDragsParticleToItsSpeed)
{
  // A particle pressed between a stage (z = 0, frictionless) and a plate above it that
  // slides along +x at 0.05 m/s with friction: it must end up moving with the plate.
  Material m = elastic_material("bead", 1e8, 0.3, 2500);
  m.damping = 0.5;
  Case c = single_species_case(m);
  const double R = 0.5e-3, gap = 2 * R - 2e-6; // 1 µm overlap on each side
  Material stage = elastic_material("stage", 1e10, 0.3, 0);
  Material plate = elastic_material("plate", 1e10, 0.3, 0);
  plate.friction = 0.5;
  c.materials.push_back(stage);
  c.materials.push_back(plate);
  PlaneWall s;
  s.name = "stage";
  s.material = "stage";
  c.planes.push_back(s);
  PlaneWall p;
  p.name = "plate";
  p.point = {0, 0, gap};
  p.normal = {0, 0, -1};
  p.material = "plate";
  p.path = {{0.0, {0, 0, 0}}, {1.0, {0.05, 0, 0}}};
  c.planes.push_back(p);
  DemSystem sys(c);
  sys.particles().add({0, 0, 0.5 * gap}, R, m.density, 0, 0.0);
  sys.initialize();
  while (sys.time() < 0.05)
    sys.step();
  const auto &q = sys.particles();
  // Contact point at the top moves with the plate: v + ω × (R n) = 0.05 m/s.
  const double top = q.vx[0] + q.wy[0] * (0.5 * gap);
  std::printf("sliding plate: particle contact-point speed %.6f m/s (plate 0.05), centre %.6f m/s\n", top, q.vx[0]);
  EXPECT_NEAR(top, 0.05, 5e-4);
  const auto loads = sys.wall_loads();
  EXPECT_EQ(loads.size(), 2u);
  EXPECT_GT(loads[1].force[2], 0.0); // the particle pushes the plate up
  EXPECT_NEAR(loads[0].force[2], -loads[1].force[2], 1e-6 * loads[1].force[2]);
}

TEST(DemWalls, WallContactRecordsCarryTheWeightOfRestingBeads)
{
  // Three beads resting on a stage under gravity (damped to rest): the stage's contact
  // records name exactly those beads, each carrying its weight m g along −z, and their sum
  // equals the total wall load.
  Material m = elastic_material("bead", 1e8, 0.3, 2500);
  m.damping = 0.9;
  Case c = single_species_case(m);
  c.dem.gravity = {0.0, 0.0, -9.81};
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1});
  DemSystem sys(c);
  const double R = 0.5e-3;
  for (int k = 0; k < 3; ++k)
    sys.particles().add({3.0 * R * k, 0, R * (1.0 + 0.1 * k)}, R * (1.0 + 0.1 * k), m.density, 0, 0.0);
  sys.particles().add({20 * R, 0, 10 * R}, R, m.density, 0, 0.0); // still in the air
  sys.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys.initialize();
  while (sys.time() < 0.004)
    sys.step();
  std::vector<WallContactRecord> rec;
  sys.wall_contacts(0, rec);
  ASSERT_EQ(rec.size(), 3u);
  const auto &q = sys.particles();
  double total = 0.0;
  for (const auto &r : rec)
  {
    EXPECT_LT(q.z[r.particle], 2 * R);
    EXPECT_NEAR(r.force_on_wall.z, -q.mass[r.particle] * 9.81, 1e-3 * q.mass[r.particle] * 9.81);
    EXPECT_NEAR(r.force_on_wall.x, 0.0, 1e-9);
    total += r.force_on_wall.z;
  }
  EXPECT_NEAR(sys.wall_loads()[0].force[2], total, 1e-12 * std::abs(total));
}

TEST(DemWalls, CylinderSpinsUpLinearly)
{
  // A sleeve with a 1 ms spin-up: surface speed ωR t/T before T, ωR after, at rest while the
  // walls are frozen (settling).
  WallSet ws;
  CylinderWall sleeve;
  sleeve.name = "sleeve";
  sleeve.radius = 10e-3;
  sleeve.omega = 20.0;
  sleeve.spin_up_time = 1e-3;
  sleeve.material = "sleeve";
  ws.cylinders.push_back(sleeve);
  DemWalls walls(ws);
  WallContactGeometry g;
  const Vector3 p{0, 10e-3 + 49e-6, 0};
  for (const double t : {0.0, 0.25e-3, 0.5e-3, 1e-3, 3e-3})
  {
    walls.prepare(t, false);
    ASSERT_TRUE(walls.contact(0, p, 50e-6, g));
    const double expected = -20.0 * 10e-3 * std::min(t / 1e-3, 1.0);
    EXPECT_NEAR(g.surface_velocity.x, expected, 1e-15) << "t = " << t;
    EXPECT_NEAR(g.angular_velocity.z, 20.0 * std::min(t / 1e-3, 1.0), 1e-12) << "t = " << t;
  }
  walls.prepare(0.5e-3, true);
  ASSERT_TRUE(walls.contact(0, p, 50e-6, g));
  EXPECT_EQ(g.surface_velocity.x, 0.0);
}
