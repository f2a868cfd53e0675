// Derived quantities of the case model (see case_model.h for conventions).
#include "case/case_model.h"

#include <cmath>
#include <stdexcept>

namespace magbrush {

namespace {
constexpr double two_pi = 2.0 * M_PI;
double rpm_to_rad_per_s(double rpm) { return rpm * two_pi / 60.0; }
} // namespace

double Sleeve::omega() const { return rpm_to_rad_per_s(rpm); }
double Sleeve::surface_speed() const { return std::abs(omega()) * radius; }

namespace {
// ∫ ω dt from 0 to t for a cylinder whose speed ramps linearly from rest over spin_up_time
// (dem/wall_contacts.cpp cylinder_omega); at rest before t = 0 (the particles settle).
double turned_with_ramp(double omega, double spin_up_time, double t)
{
  if (t <= 0.0)
    return 0.0;
  const double T = spin_up_time;
  return T > 0.0 && t < T ? 0.5 * omega * t * t / T : omega * (T > 0.0 ? t - 0.5 * T : t);
}
} // namespace

double Sleeve::turned(double t) const { return turned_with_ramp(omega(), spin_up_time, t); }

double Drum::omega() const { return rpm_to_rad_per_s(rpm); }
double Drum::turned(double t) const { return turned_with_ramp(omega(), spin_up_time, t); }

Vec2 Drum::center(double sleeve_radius) const
{
  // The drum surface is `gap` away from the sleeve surface along the line of centres.
  const double d = sleeve_radius + gap + radius;
  return {d * std::cos(angle), d * std::sin(angle)};
}

bool Case::has_charged_population() const
{
  for (const auto &p : populations)
    if (p.charge_to_mass != 0.0)
      return true;
  return false;
}

const Material &Case::material(const std::string &name) const
{
  for (const auto &m : materials)
    if (m.name == name)
      return m;
  std::string known;
  for (const auto &m : materials)
    known += (known.empty() ? "" : ", ") + m.name;
  throw std::runtime_error("case '" + source_file + "': no material named '" + name + "' (materials: " +
                           (known.empty() ? "none" : known) + "); add it under 'materials:'");
}

} // namespace magbrush
