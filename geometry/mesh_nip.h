// The Gmsh mesh of the development nip for the electrostatic problem (Kweon eq. 7–8):
// the plane outside the sleeve disk and outside the drum substrate disk, inside the
// open-boundary shell:
//
//   air              between the sleeve surface (electrode at V_bias), the drum and the shell
//   photoconductor   the layer R_drum − t_pc < |x − c_drum| < R_drum (when t_pc > 0), structured:
//                    at least 3 cells across, radial grid lines, fine in the nip and graded away
//   shell            R_in < |x − c| < R_out around a circle enclosing sleeve and drum
//
// boundaries: the sleeve surface, the grounded drum substrate (the drum surface itself when
// t_pc = 0: the bare two-cylinder problem), the outer circle of the shell. The element size is
// FieldSettings::mesh_size_gap in a disk around the middle of the development gap (out to where
// the gap has opened to 3× its width), graded to mesh_size_far.
#pragma once

#include "case/case_model.h"
#include "geometry/mesh_common.h"
#include "geometry/mesh_size.h"

#include <string>
#include <utility>
#include <vector>

namespace magbrush {

struct NipMeshGeometry
{
  double sleeve_radius = 0.0;
  Vec2 drum_center{{0.0, 0.0}};
  double drum_radius = 0.0;
  double pc_thickness = 0.0;
  double gap = 0.0;
  Vec2 nip_direction{{1.0, 0.0}}; // unit vector from the roller centre to the drum centre
  Vec2 nip_midpoint{{0.0, 0.0}};  // middle of the development gap on the line of centres
  double nip_window = 0.0;      // radius of the mesh_size_gap disk around nip_midpoint
  int layer_cells_across = 0;   // photoconductor cells across its thickness (0: no layer)
  OpenBoundaryShell shell;
};

// Throws std::invalid_argument naming the key when the case has no drum or sleeve, the gap is
// not positive, the layer is thicker than the drum, or the shell factor is ≤ 1.
NipMeshGeometry nip_mesh_geometry(const Case &c);
OpenBoundaryShell nip_shell(const Case &c);
std::vector<MeshCircle> nip_mesh_circles(const Case &c);
MeshSizeFunction nip_mesh_size(const Case &c);
std::vector<std::pair<std::string, double>> nip_exact_areas(const Case &c);

// Meshes the nip and writes `msh_path` (MSH 2.2, atomically); returns what was written.
MeshSummary write_nip_mesh(const Case &c, const std::string &msh_path, const MeshOptions &options = {});

} // namespace magbrush
