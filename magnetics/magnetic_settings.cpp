#include "magnetics/magnetic_settings.h"

#include "case/case_model.h"

#include <stdexcept>

namespace magbrush::magnetics {

DipoleModel parse_dipole_model(const std::string &name)
{
  if (name == "point_dipole")
    return DipoleModel::point_dipole;
  if (name == "mutual_dipole")
    return DipoleModel::mutual_dipole;
  if (name == "corrected")
    return DipoleModel::corrected;
  throw std::invalid_argument("magnetic model: expected one of point_dipole, mutual_dipole, "
                              "corrected; found '" + name +
                              "'. Set dem.magnetic_model to one of these.");
}

std::string to_string(DipoleModel model)
{
  switch (model)
  {
    case DipoleModel::point_dipole: return "point_dipole";
    case DipoleModel::mutual_dipole: return "mutual_dipole";
    case DipoleModel::corrected: return "corrected";
  }
  return "?";
}

FarField parse_far_field(const std::string &name)
{
  if (name == "none")
    return FarField::none;
  if (name == "cell_multipole")
    return FarField::cell_multipole;
  throw std::invalid_argument("magnetic far field: expected none or cell_multipole; found '" +
                              name + "'. Set dem.magnetic_far_field to one of these.");
}

std::string to_string(FarField far_field)
{
  return far_field == FarField::none ? "none" : "cell_multipole";
}

StalenessMode parse_staleness_mode(const std::string &name)
{
  if (name == "absolute")
    return StalenessMode::absolute;
  if (name == "local")
    return StalenessMode::local;
  if (name == "relative")
    return StalenessMode::relative;
  throw std::invalid_argument("magnetic staleness mode: expected relative, local or absolute; found '" + name +
                              "'. Set dem.magnetic_staleness_mode to one of these.");
}

std::string to_string(StalenessMode mode)
{
  switch (mode)
  {
    case StalenessMode::absolute: return "absolute";
    case StalenessMode::local: return "local";
    case StalenessMode::relative: return "relative";
  }
  return "?";
}

MagneticSettings MagneticSettings::from_case(const DemSettings &dem)
{
  MagneticSettings s;
  s.model = parse_dipole_model(dem.magnetic_model);
  s.cutoff_diameters = dem.magnetic_cutoff;
  s.tolerance = dem.magnetic_tolerance;
  s.refresh_interval = dem.magnetic_refresh;
  s.skin_fraction = dem.magnetic_skin > 0.0 ? dem.magnetic_skin : dem.verlet_skin;
  s.live_pair_steps = dem.magnetic_live_steps;
  s.far_field = parse_far_field(dem.magnetic_far_field);
  s.far_order = dem.magnetic_far_order;
  s.far_cell_diameters = dem.magnetic_far_cell;
  s.staleness_fraction = dem.magnetic_staleness;
  s.staleness_mode = parse_staleness_mode(dem.magnetic_staleness_mode);
  if (dem.magnetic_hold != "forces" && dem.magnetic_hold != "dipoles")
    throw std::invalid_argument("magnetics: unknown dem.magnetic_hold '" + dem.magnetic_hold +
                                "'. Set it to forces or dipoles.");
  s.hold_dipoles = dem.magnetic_hold == "dipoles";
  return s;
}

} // namespace magbrush::magnetics
