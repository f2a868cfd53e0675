// The Gmsh mesh of the magnet roller for the magnetostatic problem (Kweon eq. 9–10):
//
//   shaft disk            r < R_shaft            (iron, mu_r = shaft_mu_r; absent if R_shaft = 0)
//   magnet annulus        R_shaft < r < R_magnet (carries the pole magnetisation)
//   air (gap)             R_magnet < r < R_sleeve − t
//   sleeve wall           R_sleeve − t < r < R_sleeve (non-magnetic, its own region)
//   air                   R_sleeve < r < R_in, with every soft-magnetic blade (mu_r > 1)
//                         embedded as its own region
//   shell                 R_in < r < R_out (open boundary, structured)
//
// all conforming (each interface circle is one shared curve), quadrilaterals only. The element
// size is FieldSettings::mesh_size_sleeve in a band from inside the magnet surface to the outer
// edge of the DEM region (the polar field grid), graded to mesh_size_far away from it.
#pragma once

#include "case/case_model.h"
#include "geometry/mesh_common.h"
#include "geometry/mesh_size.h"

#include <string>
#include <vector>

namespace magbrush {

// The radii and parts of the roller mesh, derived from (and checked against) the case.
struct RollerMeshGeometry
{
  double shaft_radius = 0.0;
  double magnet_radius = 0.0;
  double sleeve_inner_radius = 0.0;
  double sleeve_radius = 0.0;
  double fine_band_inner = 0.0;  // the mesh_size_sleeve band
  double fine_band_outer = 0.0;
  std::vector<std::size_t> magnetic_blades; // indices into Case::blades with mu_r > 1
  OpenBoundaryShell shell;
};

// Throws std::invalid_argument naming the key when the case has no roller geometry or its
// parts do not nest (magnet larger than the sleeve bore, a magnetic blade cutting the sleeve,
// two blades overlapping, a shell factor ≤ 1).
RollerMeshGeometry roller_mesh_geometry(const Case &c);
OpenBoundaryShell roller_shell(const Case &c);
std::vector<MeshCircle> roller_mesh_circles(const Case &c);
MeshSizeFunction roller_mesh_size(const Case &c);

// The exact areas of the regions by physical-group name.
std::vector<std::pair<std::string, double>> roller_exact_areas(const Case &c);

// Meshes the roller and writes `msh_path` (MSH 2.2, atomically); returns what was written.
MeshSummary write_roller_mesh(const Case &c, const std::string &msh_path, const MeshOptions &options = {});

} // namespace magbrush
