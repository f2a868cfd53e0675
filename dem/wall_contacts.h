// The DEM's view of the walls: for each analytic primitive from geometry/wall_primitives.h
// (rotating cylinders, moving planes, extruded polygons) the contact geometry with a sphere:
// overlap, normal, and the velocity of the wall's surface at the contact point.
#pragma once

#include "dem/vector3.h"

#include "geometry/wall_primitives.h"

#include <array>
#include <string>
#include <vector>

namespace magbrush::dem {

struct WallContactGeometry
{
  double overlap = 0.0;     // δ > 0 when touching (−gap within an adhesion range)
  Vector3 n;                // unit normal from the particle centre towards the wall
  Vector3 surface_velocity; // velocity of the wall material at the contact point
  Vector3 angular_velocity; // the wall's rigid-body angular velocity
  Vector3 torque_origin;    // point about which the wall's torque is reported
};

class DemWalls
{
public:
  DemWalls() = default;
  explicit DemWalls(const WallSet &walls);

  std::size_t size() const { return walls_.size(); }
  const std::string &name(std::size_t w) const { return walls_[w].name; }
  const std::string &material(std::size_t w) const { return walls_[w].material; }
  std::vector<std::string> materials() const;

  // Moves the walls to time t (plane positions and velocities, cylinder spin-up), once per
  // step. `frozen`: walls at rest at their t = 0 position (the settling phase).
  void prepare(double t, bool frozen);

  // Contact of a sphere (centre p, radius r) with wall w at the prepared time. Returns false
  // when the gap is `range` or more (range > 0: van der Waals adhesion reaches across a gap;
  // then g.overlap may be ≤ 0, the negative gap).
  bool contact(std::size_t w, const Vector3 &p, double r, WallContactGeometry &g, double range = 0.0) const;

  // False only where contact(w, p, r_reach, ...) is certainly false (r_reach = r + range),
  // without a square root or a call: the per-particle pre-filter of the engine's wall phase.
  // Cylinders only (the walls most particles are far from); conservative by a billionth of
  // the radius, so that the exact test decides every case near the threshold.
  bool may_touch(std::size_t w, const Vector3 &p, double r_reach) const
  {
    const CylinderFilter &f = cylinder_filters_[w];
    if (!f.is_cylinder)
      return true;
    const double dx = p.x - f.cx, dy = p.y - f.cy, d2 = dx * dx + dy * dy;
    if (f.outside)
    {
      const double reach = f.radius + r_reach + f.slack; // touching: d < R + r
      return d2 < reach * reach;
    }
    const double inner = f.radius - r_reach - f.slack; // touching: d > R − r
    return inner <= 0.0 || d2 > inner * inner;
  }

  // Signed distance from p to wall w's surface at time t (> 0 on the particle side).
  double distance(std::size_t w, const Vector3 &p, double t) const;

  // Largest surface speed of any wall over the run (for the time-step criterion and guards).
  double max_surface_speed() const;

private:
  enum class Kind { cylinder, plane, prism };
  struct Wall
  {
    Kind kind;
    std::string name, material;
    std::size_t index; // into the primitive arrays below
  };
  std::vector<Wall> walls_;
  std::vector<CylinderWall> cylinders_;
  std::vector<PlaneWallPrimitive> planes_;
  std::vector<PrismWall> prisms_;
  std::vector<std::array<double, 4>> prism_boxes_; // x_min, x_max, y_min, y_max
  // State at the prepared time, per wall: plane point and velocity, cylinder ω.
  struct Current
  {
    Vector3 point, velocity;
    double omega = 0.0;
  };
  std::vector<Current> current_;
  // Per wall: what may_touch() needs of a cylinder (is_cylinder false: no pre-filter).
  struct CylinderFilter
  {
    bool is_cylinder = false, outside = true;
    double cx = 0.0, cy = 0.0, radius = 0.0, slack = 0.0;
  };
  std::vector<CylinderFilter> cylinder_filters_;

  // Closest point on polygon boundary to q; `inside` tells whether q is inside the polygon.
  static void closest_on_polygon(const std::vector<Vec2> &poly, double qx, double qy, double &cx,
                                 double &cy, bool &inside);
  double cylinder_omega(const CylinderWall &c, double t, bool frozen) const;
};

} // namespace magbrush::dem
