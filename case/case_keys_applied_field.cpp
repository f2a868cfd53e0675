// Case keys of module "applied_field" (the list of modules and why it is explicit: case_keys.h).
// The applied magnetic field the DEM beads sit in: the roller's stored field or a uniform
// field with its ramp or schedule. Read by fields/applied_magnetic_field.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> applied_field_keys()
{
  return {
      section("applied_field", "Where the magnetic field comes from: the roller (field solver grid) or uniform."),
      choice("applied_field.kind", {"auto", "none", "roller", "uniform"}, "auto: roller if a roller is given, else none.")
          .def("auto"),
      vector3("applied_field.direction", D::dimensionless, "Uniform field direction (normalised).").def("[0, 0, 1]"),
      quantity("applied_field.magnitude", D::magnetic_flux_density, "Uniform |B| at the end of the ramp.")
          .def("0 mT").non_negative(),
      quantity("applied_field.ramp_time", D::time, "Linear ramp 0 -> |B| over this time (0 = on at once).")
          .def("0 s").non_negative(),
      list("applied_field.schedule",
           "Uniform field only: piecewise-linear |B|(t) as (time, magnitude) samples, times increasing, held "
           "before the first and after the last (replaces magnitude and ramp_time; e.g. a field sweep at a held plate)."),
      quantity("applied_field.schedule[].time", D::time, "Sample time.").required().non_negative(),
      quantity("applied_field.schedule[].magnitude", D::magnetic_flux_density, "|B| at that time.")
          .required().non_negative(),
  };
}

} // namespace magbrush::case_keys
