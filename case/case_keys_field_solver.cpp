// Case keys of module "field" (the list of modules and why it is explicit: case_keys.h).
// The field solver: mesh sizes, element degree, the exported field grids. Read by
// field_solver/ and geometry/ (mesh sizes), and by the field-grid bookkeeping in fields/.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> field_solver_keys()
{
  return {
      section("field", "Field solver: meshes, element degree, exported grids."),
      quantity("field.mesh_size_far", D::length, "Element size away from the sleeve.").def("2 mm").positive().affects(A::both),
      quantity("field.mesh_size_sleeve", D::length, "Element size at the sleeve surface (with degree 3: 3e-4 max B error on the sleeve, measured).").def("0.25 mm").positive().affects(A::both),
      quantity("field.mesh_size_gap", D::length, "Element size in the development gap.").def("20 um").positive().affects(A::both),
      integer("field.element_degree", "Finite-element degree (3: the cheapest for 1e-3 in B, tests/field_solver bench).").def("3").min(1).max(4).affects(A::both),
      number("field.outer_radius_factor", "Open-boundary shell starts at this x sleeve radius.")
          .def("2").min(1.0, false).affects(A::both),
      quantity("field.grid_radial_spacing", D::length, "Polar magnetic grid radial spacing.").def("50 um").positive().affects(A::magnetic),
      quantity("field.grid_angular_spacing", D::angle, "Polar magnetic grid angular spacing.").def("0.25 deg").positive().affects(A::magnetic),
      quantity("field.grid_outer_radius", D::length, "Polar grid outer radius (0 = sleeve + 3 mm).").def("0 mm").non_negative().affects(A::magnetic),
      quantity("field.grid_electric_spacing", D::length, "Cartesian nip grid spacing.").def("10 um").positive().affects(A::electric),
      integer("field.electric_phase_samples", "Phases of the moving latent image stored per image period (the DEM interpolates between them; docs/electrostatics.md).")
          .def("16").min(1).max(1024).affects(A::electric),
      quantity("field.probe_radius", D::length, "Radius of the exported sleeve flux profile (0 = sleeve radius).")
          .def("0 mm").non_negative().affects(A::magnetic),
      text("field.output_dir", "Directory of the stored field files (empty: <output.directory>/fields).").def(""),
  };
}

} // namespace magbrush::case_keys
