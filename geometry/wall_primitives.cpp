// Builds the DEM's analytic walls from the case (see wall_primitives.h).
#include "wall_primitives.h"

#include <algorithm>

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
    drum.particles_outside = true;
    drum.material = "drum";
    walls.cylinders.push_back(drum);
  }
  for (const auto &b : c.blades)
    walls.prisms.push_back({b.name, b.polygon, b.material});
  for (const auto &p : c.planes)
    walls.planes.push_back({p.name, p.point, p.normal, p.material, p.path});
  return walls;
}

} // namespace magbrush
