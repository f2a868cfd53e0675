// Analytic wall primitives for the DEM, built from the same case description as the meshes,
// so that the FEM and the DEM can never disagree about where a surface is.
//
// All walls are infinite along the roller axis z (the DEM is periodic along z), except
// planes, which may have any orientation (Kawamoto's compression stage and plate).
// This header has no Gmsh in it: the DEM links the `magbrush_walls` library only.
#pragma once

#include "case/case_model.h"
#include "case/case_validation.h" // polygon_signed_area, polygon_is_simple (shared with the parser)

#include <string>
#include <utility>
#include <vector>

namespace magbrush {

// A circular cylinder with axis parallel to z through `center`, rotating rigidly at
// `omega` [rad/s] (counter-clockwise positive). Sleeve and drum.
struct CylinderWall
{
  std::string name;
  Vec2 center{0.0, 0.0};
  double radius = 0.0;
  double omega = 0.0;            // surface velocity = ω ẑ × (x − c)
  bool particles_outside = true; // true: particles live outside (sleeve, drum)
  std::string material;
  double spin_up_time = 0.0;     // linear ramp of ω from 0 over this time [s]

  // Rigid-rotation velocity of the surface material at `x` (any point, in the x-y plane):
  // ω ẑ × (x − c). Seen from +z, ω > 0 turns counter-clockwise.
  Vec2 surface_velocity(const Vec2 &x) const;
};

// An infinite plane through `point` with unit `normal` pointing into the particle side.
// Its point moves on a piecewise-linear prescribed path (t, displacement), e.g. the
// compression plate coming down and then sliding sideways.
struct PlaneWallPrimitive
{
  std::string name;
  Vec3 point{0.0, 0.0, 0.0};
  Vec3 normal{0.0, 0.0, 1.0};
  std::string material;
  std::vector<std::pair<double, Vec3>> path; // empty = static

  Vec3 displacement(double t) const;          // offset of `point` at time t
  Vec3 velocity(double t) const;              // d(displacement)/dt at time t
};

// A polygon in the x-y plane extruded along z: doctor blade, guides. Static.
struct PrismWall
{
  std::string name;
  std::vector<Vec2> polygon;     // counter-clockwise, closed implicitly
  std::string material;
};

struct WallSet
{
  std::vector<CylinderWall> cylinders;
  std::vector<PlaneWallPrimitive> planes;
  std::vector<PrismWall> prisms;

  const CylinderWall *cylinder(const std::string &name) const; // nullptr if absent
};

// The walls a case implies: sleeve (and drum, when present) as rotating cylinders,
// blades and guides as prisms (polygons made counter-clockwise), explicit plane walls as
// planes. Throws when a blade polygon is degenerate (fewer than 3 vertices, zero area,
// self-intersecting).
WallSet build_wall_primitives(const Case &c);

// Speed of the sleeve surface relative to the drum surface at the nip point (the slip
// speed Kawamoto measures, 0.135 m/s for his prototype): the difference of the two
// tangential surface velocities on the line of centres. Both surfaces moving the same way
// (sleeve and drum turning in opposite senses) gives the difference of the surface speeds.
double nip_relative_surface_speed(const WallSet &walls);

// ---- plane polygon helpers (shared by the walls and the meshes) ----------------------------
std::vector<Vec2> counter_clockwise(std::vector<Vec2> polygon);   // reversed if clockwise
bool point_in_polygon(const Vec2 &p, const std::vector<Vec2> &polygon);
double distance_to_segment(const Vec2 &p, const Vec2 &a, const Vec2 &b);
double distance_to_polygon_boundary(const Vec2 &p, const std::vector<Vec2> &polygon);
bool segments_cross(const Vec2 &a, const Vec2 &b, const Vec2 &c, const Vec2 &d); // incl. touching
bool polygons_overlap(const std::vector<Vec2> &p, const std::vector<Vec2> &q); // cross or nest

} // namespace magbrush
