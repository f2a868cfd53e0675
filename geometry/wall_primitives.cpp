// Builds the DEM's analytic walls from the case (see wall_primitives.h).
#include "geometry/wall_primitives.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace magbrush {

namespace {
// Piecewise-linear interpolation of the prescribed path; constant beyond its ends.
Vec3 interpolate_path(const std::vector<std::pair<double, Vec3>> &path, double t)
{
  if (path.empty())
    return {0.0, 0.0, 0.0};
  if (t <= path.front().first)
    return path.front().second;
  if (t >= path.back().first)
    return path.back().second;
  const auto hi = std::upper_bound(path.begin(), path.end(), t,
                                   [](double v, const auto &p) { return v < p.first; });
  const auto lo = hi - 1;
  const double s = (t - lo->first) / (hi->first - lo->first);
  Vec3 r;
  for (int k = 0; k < 3; ++k)
    r[k] = lo->second[k] + s * (hi->second[k] - lo->second[k]);
  return r;
}
} // namespace

Vec3 PlaneWallPrimitive::displacement(double t) const { return interpolate_path(path, t); }

Vec3 PlaneWallPrimitive::velocity(double t) const
{
  if (path.size() < 2 || t < path.front().first || t >= path.back().first)
    return {0.0, 0.0, 0.0};
  const auto hi = std::upper_bound(path.begin(), path.end(), t,
                                   [](double v, const auto &p) { return v < p.first; });
  const auto lo = hi - 1;
  const double dt = hi->first - lo->first;
  Vec3 v;
  for (int k = 0; k < 3; ++k)
    v[k] = (hi->second[k] - lo->second[k]) / dt;
  return v;
}

Vec2 CylinderWall::surface_velocity(const Vec2 &x) const
{
  return {-omega * (x[1] - center[1]), omega * (x[0] - center[0])};
}

const CylinderWall *WallSet::cylinder(const std::string &name) const
{
  for (const auto &w : cylinders)
    if (w.name == name)
      return &w;
  return nullptr;
}

namespace {
double cross(const Vec2 &o, const Vec2 &a, const Vec2 &b)
{
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// A blade polygon the DEM and the mesher can both use: ≥ 3 vertices, a real area, simple.
void check_blade_polygon(const BladeOrGuide &b)
{
  const std::string what = "blade/guide '" + b.name + "': ";
  if (b.polygon.size() < 3)
    throw std::invalid_argument(what + "its polygon has " + std::to_string(b.polygon.size()) +
                                " vertices; a wall polygon needs at least 3");
  double extent = 0.0;
  for (const auto &v : b.polygon)
    extent = std::max({extent, std::abs(v[0]), std::abs(v[1])});
  if (std::abs(polygon_signed_area(b.polygon)) <= 1e-12 * extent * extent)
    throw std::invalid_argument(what + "its polygon has zero area (collinear vertices?); "
                                       "give the outline of the plate");
  if (!polygon_is_simple(b.polygon))
    throw std::invalid_argument(what + "its polygon crosses itself; list the vertices in order "
                                       "around the outline");
}
} // namespace

std::vector<Vec2> counter_clockwise(std::vector<Vec2> polygon)
{
  if (polygon_signed_area(polygon) < 0.0)
    std::reverse(polygon.begin(), polygon.end());
  return polygon;
}

bool point_in_polygon(const Vec2 &p, const std::vector<Vec2> &polygon)
{
  // Crossing number of a ray towards +x.
  bool inside = false;
  for (size_t i = 0, n = polygon.size(), j = n - 1; i < n; j = i++)
  {
    const Vec2 &a = polygon[i], &b = polygon[j];
    if ((a[1] > p[1]) != (b[1] > p[1]) &&
        p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0])
      inside = !inside;
  }
  return inside;
}

double distance_to_segment(const Vec2 &p, const Vec2 &a, const Vec2 &b)
{
  const double ex = b[0] - a[0], ey = b[1] - a[1];
  const double len2 = ex * ex + ey * ey;
  double s = len2 > 0.0 ? ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  return std::hypot(p[0] - (a[0] + s * ex), p[1] - (a[1] + s * ey));
}

double distance_to_polygon_boundary(const Vec2 &p, const std::vector<Vec2> &polygon)
{
  double d = INFINITY;
  for (size_t i = 0, n = polygon.size(); i < n; ++i)
    d = std::min(d, distance_to_segment(p, polygon[i], polygon[(i + 1) % n]));
  return d;
}

bool segments_cross(const Vec2 &a, const Vec2 &b, const Vec2 &c, const Vec2 &d)
{
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  // Touching or collinear overlap: an end point on the other segment.
  const double scale = std::max({std::hypot(b[0] - a[0], b[1] - a[1]),
                                 std::hypot(d[0] - c[0], d[1] - c[1])});
  const double tol = 1e-12 * scale;
  return distance_to_segment(a, c, d) <= tol || distance_to_segment(b, c, d) <= tol ||
         distance_to_segment(c, a, b) <= tol || distance_to_segment(d, a, b) <= tol;
}

bool polygons_overlap(const std::vector<Vec2> &p, const std::vector<Vec2> &q)
{
  for (size_t i = 0; i < p.size(); ++i)
    for (size_t j = 0; j < q.size(); ++j)
      if (segments_cross(p[i], p[(i + 1) % p.size()], q[j], q[(j + 1) % q.size()]))
        return true;
  return point_in_polygon(p.front(), q) || point_in_polygon(q.front(), p);
}

double nip_relative_surface_speed(const WallSet &walls)
{
  const CylinderWall *sleeve = walls.cylinder("sleeve"), *drum = walls.cylinder("drum");
  if (!sleeve || !drum)
    throw std::invalid_argument("nip_relative_surface_speed: the scene has no " +
                                std::string(!sleeve ? "sleeve" : "drum") +
                                "; a nip needs both (set drum.present / sleeve in the case)");
  // Unit vector of the line of centres, and the tangent along which both surfaces move.
  const double dx = drum->center[0] - sleeve->center[0], dy = drum->center[1] - sleeve->center[1];
  const double d = std::hypot(dx, dy);
  const Vec2 n{dx / d, dy / d}, t{-n[1], n[0]};
  const Vec2 on_sleeve{sleeve->center[0] + sleeve->radius * n[0],
                       sleeve->center[1] + sleeve->radius * n[1]};
  const Vec2 on_drum{drum->center[0] - drum->radius * n[0], drum->center[1] - drum->radius * n[1]};
  const Vec2 vs = sleeve->surface_velocity(on_sleeve), vd = drum->surface_velocity(on_drum);
  return (vs[0] - vd[0]) * t[0] + (vs[1] - vd[1]) * t[1];
}

WallSet build_wall_primitives(const Case &c)
{
  WallSet walls;
  if (c.sleeve)
  {
    CylinderWall sleeve;
    sleeve.name = "sleeve";
    sleeve.center = {0.0, 0.0};
    sleeve.radius = c.sleeve->radius;
    sleeve.omega = c.sleeve->omega();
    sleeve.spin_up_time = c.sleeve->spin_up_time;
    sleeve.particles_outside = true;
    sleeve.material = "sleeve";
    walls.cylinders.push_back(sleeve);
  }
  if (c.drum.present && c.sleeve)
  {
    CylinderWall drum;
    drum.name = "drum";
    drum.center = c.drum.center(c.sleeve->radius);
    drum.radius = c.drum.radius;
    drum.omega = c.drum.omega();
    drum.spin_up_time = c.drum.spin_up_time;
    drum.particles_outside = true;
    drum.material = "drum";
    walls.cylinders.push_back(drum);
  }
  for (const auto &b : c.blades)
  {
    check_blade_polygon(b);
    walls.prisms.push_back({b.name, counter_clockwise(b.polygon), b.material});
  }
  for (const auto &p : c.planes)
    walls.planes.push_back({p.name, p.point, p.normal, p.material, p.path});
  return walls;
}

} // namespace magbrush
