// Sphere–wall contact geometry for the analytic primitives (see wall_contacts.h).
#include "dem/wall_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace magbrush::dem {

DemWalls::DemWalls(const WallSet &walls)
{
  for (const auto &c : walls.cylinders)
  {
    if (!(c.radius > 0.0))
      throw std::invalid_argument("wall '" + c.name + "': cylinder radius must be > 0");
    walls_.push_back({Kind::cylinder, c.name, c.material, cylinders_.size()});
    cylinders_.push_back(c);
  }
  for (auto p : walls.planes)
  {
    const double l = std::sqrt(p.normal[0] * p.normal[0] + p.normal[1] * p.normal[1] + p.normal[2] * p.normal[2]);
    if (!(l > 0.0))
      throw std::invalid_argument("wall '" + p.name + "': plane normal must be non-zero");
    for (auto &v : p.normal)
      v /= l;
    walls_.push_back({Kind::plane, p.name, p.material, planes_.size()});
    planes_.push_back(p);
  }
  for (const auto &q : walls.prisms)
  {
    if (q.polygon.size() < 3)
      throw std::invalid_argument("wall '" + q.name + "': a prism needs a polygon of at least 3 points");
    walls_.push_back({Kind::prism, q.name, q.material, prisms_.size()});
    prisms_.push_back(q);
    std::array<double, 4> b{q.polygon[0][0], q.polygon[0][0], q.polygon[0][1], q.polygon[0][1]};
    for (const auto &v : q.polygon)
    {
      b[0] = std::min(b[0], v[0]);
      b[1] = std::max(b[1], v[0]);
      b[2] = std::min(b[2], v[1]);
      b[3] = std::max(b[3], v[1]);
    }
    prism_boxes_.push_back(b);
  }
  cylinder_filters_.resize(walls_.size());
  for (std::size_t w = 0; w < walls_.size(); ++w)
    if (walls_[w].kind == Kind::cylinder)
    {
      const CylinderWall &c = cylinders_[walls_[w].index];
      cylinder_filters_[w] = {true, c.particles_outside, c.center[0], c.center[1], c.radius, 1e-9 * c.radius};
    }
}

std::vector<std::string> DemWalls::materials() const
{
  std::vector<std::string> m;
  for (const auto &w : walls_)
    m.push_back(w.material);
  return m;
}

double DemWalls::cylinder_omega(const CylinderWall &c, double t, bool frozen) const
{
  if (frozen)
    return 0.0;
  if (c.spin_up_time > 0.0 && t < c.spin_up_time)
    return c.omega * t / c.spin_up_time;
  return c.omega;
}

double DemWalls::max_surface_speed() const
{
  double v = 0.0;
  for (const auto &c : cylinders_)
    v = std::max(v, std::abs(c.omega) * c.radius);
  for (const auto &p : planes_)
    for (std::size_t k = 1; k < p.path.size(); ++k)
    {
      const double dt = p.path[k].first - p.path[k - 1].first;
      if (dt <= 0)
        continue;
      double d2 = 0;
      for (int a = 0; a < 3; ++a)
        d2 += std::pow(p.path[k].second[a] - p.path[k - 1].second[a], 2);
      v = std::max(v, std::sqrt(d2) / dt);
    }
  return v;
}

void DemWalls::closest_on_polygon(const std::vector<Vec2> &poly, double qx, double qy, double &cx,
                                  double &cy, bool &inside)
{
  double best = std::numeric_limits<double>::max();
  inside = false;
  const std::size_t n = poly.size();
  for (std::size_t k = 0, prev = n - 1; k < n; prev = k++)
  {
    const double ax = poly[prev][0], ay = poly[prev][1], bx = poly[k][0], by = poly[k][1];
    const double ex = bx - ax, ey = by - ay;
    const double l2 = ex * ex + ey * ey;
    double s = l2 > 0 ? ((qx - ax) * ex + (qy - ay) * ey) / l2 : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    const double px = ax + s * ex, py = ay + s * ey;
    const double d2 = (qx - px) * (qx - px) + (qy - py) * (qy - py);
    if (d2 < best)
    {
      best = d2;
      cx = px;
      cy = py;
    }
    // Even–odd ray casting along +x.
    if ((ay > qy) != (by > qy) && qx < ax + (qy - ay) * ex / ey)
      inside = !inside;
  }
}

double DemWalls::distance(std::size_t w, const Vector3 &p, double t) const
{
  const Wall &wall = walls_[w];
  switch (wall.kind)
  {
  case Kind::cylinder:
  {
    const auto &c = cylinders_[wall.index];
    const double d = std::hypot(p.x - c.center[0], p.y - c.center[1]);
    return c.particles_outside ? d - c.radius : c.radius - d;
  }
  case Kind::plane:
  {
    const auto &pl = planes_[wall.index];
    const Vec3 off = pl.displacement(t);
    return (p.x - pl.point[0] - off[0]) * pl.normal[0] + (p.y - pl.point[1] - off[1]) * pl.normal[1] +
           (p.z - pl.point[2] - off[2]) * pl.normal[2];
  }
  case Kind::prism:
  {
    double cx = 0, cy = 0;
    bool inside = false;
    closest_on_polygon(prisms_[wall.index].polygon, p.x, p.y, cx, cy, inside);
    const double d = std::hypot(p.x - cx, p.y - cy);
    return inside ? -d : d;
  }
  }
  return 0.0;
}

void DemWalls::prepare(double t, bool frozen)
{
  current_.resize(walls_.size());
  for (std::size_t w = 0; w < walls_.size(); ++w)
  {
    const Wall &wall = walls_[w];
    Current &c = current_[w];
    if (wall.kind == Kind::cylinder)
      c.omega = cylinder_omega(cylinders_[wall.index], t, frozen);
    else if (wall.kind == Kind::plane)
    {
      const auto &pl = planes_[wall.index];
      const Vec3 off = pl.displacement(frozen ? 0.0 : t);
      const Vec3 v = frozen ? Vec3{0, 0, 0} : pl.velocity(t);
      c.point = {pl.point[0] + off[0], pl.point[1] + off[1], pl.point[2] + off[2]};
      c.velocity = {v[0], v[1], v[2]};
    }
  }
}

bool DemWalls::contact(std::size_t w, const Vector3 &p, double r_touch, WallContactGeometry &g, double range) const
{
  // Detected out to r_touch + range; the overlap stays measured from r_touch. (range = 0:
  // r_touch + 0 is r_touch exactly.)
  const double r = r_touch + range;
  const Wall &wall = walls_[w];
  switch (wall.kind)
  {
  case Kind::cylinder:
  {
    const auto &c = cylinders_[wall.index];
    const double dx = p.x - c.center[0], dy = p.y - c.center[1];
    const double d = std::sqrt(dx * dx + dy * dy);
    const double gap = c.particles_outside ? d - c.radius : c.radius - d;
    if (gap >= r || d == 0.0)
      return false;
    g.overlap = r_touch - gap;
    // Outside: the wall is towards the axis; inside: away from it.
    const double s = c.particles_outside ? -1.0 / d : 1.0 / d;
    g.n = {s * dx, s * dy, 0.0};
    const double om = current_[w].omega;
    // Surface point on the cylinder along the line of centres.
    const double ux = dx / d * c.radius, uy = dy / d * c.radius;
    g.surface_velocity = {-om * uy, om * ux, 0.0};
    g.angular_velocity = {0.0, 0.0, om};
    g.torque_origin = {c.center[0], c.center[1], p.z};
    return true;
  }
  case Kind::plane:
  {
    const auto &pl = planes_[wall.index];
    const Vector3 n{pl.normal[0], pl.normal[1], pl.normal[2]};
    const double gap = dot(p - current_[w].point, n);
    if (gap >= r)
      return false;
    g.overlap = r_touch - gap;
    g.n = -n;
    g.surface_velocity = current_[w].velocity;
    g.angular_velocity = {};
    g.torque_origin = {0.0, 0.0, p.z};
    return true;
  }
  case Kind::prism:
  {
    const auto &pr = prisms_[wall.index];
    const auto &b = prism_boxes_[wall.index];
    if (p.x < b[0] - r || p.x > b[1] + r || p.y < b[2] - r || p.y > b[3] + r)
      return false; // far from the blade: the common case
    double cx = 0, cy = 0;
    bool inside = false;
    closest_on_polygon(pr.polygon, p.x, p.y, cx, cy, inside);
    const double dx = p.x - cx, dy = p.y - cy;
    const double d = std::sqrt(dx * dx + dy * dy);
    const double gap = inside ? -d : d;
    if (gap >= r || d == 0.0)
      return false;
    g.overlap = r_touch - gap;
    // Outside: from the centre towards the closest boundary point; inside: the opposite
    // (push the particle back out through the nearest face).
    const double s = inside ? 1.0 / d : -1.0 / d;
    g.n = {s * dx, s * dy, 0.0};
    g.surface_velocity = {};
    g.angular_velocity = {};
    g.torque_origin = {0.0, 0.0, p.z};
    return true;
  }
  }
  return false;
}

} // namespace magbrush::dem
