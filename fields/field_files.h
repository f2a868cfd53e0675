// Where the field stage stores its outputs (header-only, no deal.II: the DEM and the tools may
// include it to find the grids). Relative output directories are relative to the working
// directory of the run.
//   <field.output_dir>/<case name>_magnetic.h5          A_z of the roller on the polar grid
//   <field.output_dir>/<case name>_electric.h5          Φ on the Cartesian window over the nip
//   <field.output_dir>/<case name>_profile_sleeve.csv   angle_deg,Bn_T,Bt_T at the sleeve surface
//   <field.output_dir>/<case name>_profile_probe.csv    the same at field.probe_radius
//   <field.output_dir>/<case name>_magnetic_0.pvtu, _electric_0.pvtu (+ .vtu)   ParaView
#pragma once

#include "case/case_model.h"

#include <string>

namespace magbrush::field {

inline std::string field_file(const Case &c, const std::string &suffix)
{
  return c.field.output_dir + "/" + c.name + "_" + suffix;
}
inline std::string magnetic_grid_path(const Case &c) { return field_file(c, "magnetic.h5"); }
inline std::string electric_grid_path(const Case &c) { return field_file(c, "electric.h5"); }

} // namespace magbrush::field
