// The nip coordinate frame (see nip_frame.h).
#include "dem/measurements/nip_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace magbrush::dem {

bool NipFrame::applies(const Case &c)
{
  return c.sleeve.has_value() && c.drum.present && c.dem.periodic_length > 0.0;
}

NipFrame NipFrame::from_case(const Case &c)
{
  if (!c.sleeve || !c.drum.present)
    throw std::invalid_argument("nip measurements: the case '" + c.name + "' has no " +
                                std::string(!c.sleeve ? "sleeve" : "drum") +
                                "; a development nip needs both (add the section to the case)");
  if (c.dem.periodic_length <= 0.0)
    throw std::invalid_argument("nip measurements: the case '" + c.name +
                                "' has no periodic slab along the roller axis (dem.periodic_length = 0); pressures and "
                                "densities are per slab area, so give the slab depth, e.g. dem.periodic_length: 1 mm");
  NipFrame f;
  f.sleeve_radius = c.sleeve->radius;
  f.drum_radius = c.drum.radius;
  const Vec2 centre = c.drum.center(c.sleeve->radius);
  f.cx = centre[0];
  f.cy = centre[1];
  const double d = std::hypot(f.cx - f.sx, f.cy - f.sy);
  f.nx = (f.cx - f.sx) / d;
  f.ny = (f.cy - f.sy) / d;
  f.sleeve_omega = c.sleeve->omega();
  f.drum_omega = c.drum.omega();
  // Downstream: the direction the sleeve surface moves at the nip (ẑ × n for a
  // counter-clockwise sleeve). A sleeve at rest keeps the counter-clockwise orientation.
  const double sense = f.sleeve_omega < 0.0 ? -1.0 : 1.0;
  f.tx = -sense * f.ny;
  f.ty = sense * f.nx;
  f.gap = c.drum.gap;
  f.slab_depth = c.dem.periodic_length;
  return f;
}

double NipFrame::x_along(double px, double py) const
{
  const double h = sleeve_radius + 0.5 * gap; // P0 = S + h n; P0·t = S·t
  return (px - sx - h * nx) * tx + (py - sy - h * ny) * ty;
}

double NipFrame::radial_gap(double theta) const
{
  // The point S + λ u on the radius u = cos θ n + sin θ t lies on the drum where
  // λ² − 2 λ D cos θ + D² − Rd² = 0 (D = |C − S|); the nearer root is the drum's near side.
  const double D = std::hypot(cx - sx, cy - sy);
  const double disc = drum_radius * drum_radius - D * D * std::sin(theta) * std::sin(theta);
  if (disc < 0.0 || std::cos(theta) <= 0.0)
    return std::numeric_limits<double>::quiet_NaN();
  return D * std::cos(theta) - std::sqrt(disc) - sleeve_radius;
}

double NipFrame::sleeve_angle(double px, double py) const
{
  const double rx = px - sx, ry = py - sy;
  return std::atan2(rx * tx + ry * ty, rx * nx + ry * ny);
}

double NipFrame::drum_angle(double px, double py) const
{
  const double rx = px - cx, ry = py - cy;
  return std::atan2(rx * tx + ry * ty, -(rx * nx + ry * ny));
}

double NipFrame::drum_angle_of_x(double x) const { return std::asin(std::clamp(x / drum_radius, -1.0, 1.0)); }
double NipFrame::drum_arc_of_x(double x) const { return drum_radius * drum_angle_of_x(x); }
double NipFrame::sleeve_angle_of_x(double x) const { return std::asin(std::clamp(x / sleeve_radius, -1.0, 1.0)); }

Vector3 NipFrame::drum_surface_velocity(double px, double py) const
{
  return {-drum_omega * (py - cy), drum_omega * (px - cx), 0.0};
}

double NipFrame::relative_surface_speed() const
{
  // Surface points on the line of centres: sleeve S + Rs n, drum C − Rd n.
  const double vs = sleeve_omega * sleeve_radius; // along ẑ × n
  const double vd = -drum_omega * drum_radius;    // drum point at −Rd n moves along −(ẑ × n) for ω > 0
  const double along = (-ny) * tx + nx * ty;      // (ẑ × n)·t = ±1
  return (vs - vd) * along;
}

} // namespace magbrush::dem
