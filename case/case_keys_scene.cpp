// Case keys of module "scene" (the list of modules and why it is explicit: case_keys.h).
// The scene as a whole: its name, its kind, and the measured flux scan to compare with (and
// the scan's angular origin).
// Read by the driver (output names, `magbrush flux`, the report) and by the case validation
// (which sections a roller or a box scene needs).
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> scene_keys()
{
  return {
      text("name", "Scene name used in output file names.").def("<file stem>"),
      choice("scene", {"roller", "box"},
             "roller: sleeve with magnet roller (optional drum, blades); box: plane walls only "
             "(Kawamoto's compression test).")
          .def("roller"),
      text("measured_flux_file", "Optional gaussmeter scan (CSV: angle_deg, Bn_mT, Bt_mT) overlaid in the report; relative to the case file.")
          .def(""),
      quantity("measured_flux_angle_origin", D::angle,
               "Roller angle (counter-clockwise from +x) at which the scan's angle reads 0: roller angle = scan angle + this. "
               "`magbrush flux --fit` writes the fitted encoder offset here; every comparison with the scan applies it. About the scan only: changes no field.")
          .def("0 deg").min(-pi).max(pi),
  };
}

} // namespace magbrush::case_keys
