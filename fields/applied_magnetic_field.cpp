// Construction of the applied magnetic field from the case (see applied_magnetic_field.h).
#include "fields/applied_magnetic_field.h"

#include "case/case_hash.h"
#include "fields/field_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush {

namespace {
void check_ramp(double ramp_time)
{
  if (!(std::isfinite(ramp_time) && ramp_time >= 0.0))
    throw std::invalid_argument("applied magnetic field: ramp_time must be ≥ 0 s, found " +
                                std::to_string(ramp_time));
}
} // namespace

AppliedMagneticField AppliedMagneticField::uniform(const Vec3 &direction, double magnitude,
                                                   double ramp_time)
{
  check_ramp(ramp_time);
  const double norm = std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                                direction[2] * direction[2]);
  if (!(norm > 0.0 && std::isfinite(norm)))
    throw std::invalid_argument(
        "applied magnetic field: the uniform field direction must be a non-zero vector "
        "(applied_field.direction), found (" +
        std::to_string(direction[0]) + ", " + std::to_string(direction[1]) + ", " +
        std::to_string(direction[2]) + ")");
  if (!std::isfinite(magnitude))
    throw std::invalid_argument("applied magnetic field: the uniform field magnitude must be finite");
  AppliedMagneticField f;
  f.kind_ = Kind::uniform;
  for (int i = 0; i < 3; ++i)
    f.uniform_B_[i] = magnitude * direction[i] / norm;
  f.ramp_time_ = ramp_time;
  return f;
}

AppliedMagneticField AppliedMagneticField::uniform_schedule(
    const Vec3 &direction, const std::vector<std::pair<double, double>> &schedule)
{
  double peak = 0.0;
  for (std::size_t i = 0; i < schedule.size(); ++i)
  {
    const auto &[t, b] = schedule[i];
    if (!(std::isfinite(t) && std::isfinite(b) && b >= 0.0))
      throw std::invalid_argument("applied magnetic field: schedule sample " + std::to_string(i) +
                                  " must have a finite time and a magnitude ≥ 0, found (" + std::to_string(t) +
                                  " s, " + std::to_string(b) + " T)");
    if (i > 0 && !(t > schedule[i - 1].first))
      throw std::invalid_argument("applied magnetic field: schedule times must increase; sample " +
                                  std::to_string(i) + " at " + std::to_string(t) + " s follows " +
                                  std::to_string(schedule[i - 1].first) + " s");
    peak = std::max(peak, b);
  }
  if (!(peak > 0.0))
    throw std::invalid_argument(
        "applied magnetic field: a schedule needs at least one sample with |B| > 0 (applied_field.schedule)");
  AppliedMagneticField f = uniform(direction, peak);
  for (const auto &[t, b] : schedule)
    f.schedule_.emplace_back(t, b / peak);
  return f;
}

AppliedMagneticField AppliedMagneticField::roller(std::shared_ptr<const PolarFieldInterpolator> grid,
                                                  double ramp_time)
{
  check_ramp(ramp_time);
  if (!grid)
    throw std::invalid_argument(
        "applied magnetic field: the roller field needs its polar grid (run `magbrush field "
        "CASE` and read the magnetic grid file), but none was given");
  AppliedMagneticField f;
  f.kind_ = Kind::roller;
  f.ramp_time_ = ramp_time;
  f.grid_ = std::move(grid);
  return f;
}

AppliedMagneticField AppliedMagneticField::from_settings(
    const AppliedField &settings, std::shared_ptr<const PolarFieldInterpolator> grid)
{
  switch (settings.kind)
  {
  case AppliedField::Kind::none:
    return AppliedMagneticField();
  case AppliedField::Kind::uniform:
    if (!settings.schedule.empty())
      return uniform_schedule(settings.uniform_direction, settings.schedule);
    return uniform(settings.uniform_direction, settings.uniform_magnitude, settings.ramp_time);
  case AppliedField::Kind::roller:
    return roller(std::move(grid), settings.ramp_time);
  }
  throw std::invalid_argument("applied magnetic field: unknown kind");
}

AppliedMagneticField AppliedMagneticField::for_case(const Case &c, const std::string &grid_path)
{
  if (c.applied_field.kind != AppliedField::Kind::roller)
    return from_settings(c.applied_field);
  const MagneticGridFile file = read_magnetic_grid(grid_path);
  check_provenance(file.info, field_inputs(c, FieldKind::magnetic));
  return roller(std::make_shared<const PolarFieldInterpolator>(file.grid), c.applied_field.ramp_time);
}

const char *AppliedMagneticField::kind_name() const
{
  switch (kind_)
  {
  case Kind::none:
    return "none";
  case Kind::uniform:
    return "uniform";
  case Kind::roller:
    return "roller grid";
  }
  return "?";
}

} // namespace magbrush
