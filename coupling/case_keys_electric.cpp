// Case keys of module "electric" (the list of modules and why it is explicit: case_keys.h).
// Nip electrostatics: sleeve bias and latent image. Read by the field solver's electrostatic
// problem (field_solver/).
#include "coupling/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> electric_keys()
{
  return {
      section("electric", "Nip electrostatics: sleeve bias against the grounded drum substrate, latent image."),
      boolean("electric.enabled", "Solve the nip field (default: true when this section is present).")
          .def("true").affects(A::electric),
      quantity("electric.bias", D::voltage, "Sleeve potential against the drum substrate (DC).")
          .def("0 V").affects(A::electric),
      section("electric.image", "Latent image strips: give dark/light potentials OR dark/light charges."),
      quantity("electric.image.dark_potential", D::voltage, "Surface potential of the unexposed areas.")
          .affects(A::electric),
      quantity("electric.image.light_potential", D::voltage, "Surface potential of the exposed (image) areas.")
          .affects(A::electric),
      quantity("electric.image.dark_charge", D::surface_charge, "Surface charge of the unexposed areas.")
          .affects(A::electric),
      quantity("electric.image.light_charge", D::surface_charge, "Surface charge of the exposed (image) areas.")
          .affects(A::electric),
      quantity("electric.image.period", D::length, "Strip period along the drum surface (0 = uniform dark).")
          .def("0 mm").non_negative().affects(A::electric),
      number("electric.image.duty", "Exposed fraction of one period.").def("0.5").min(0.0).max(1.0).affects(A::electric),
      quantity("electric.image.edge_width", D::length, "Width of the smooth (raised-cosine) transition at each strip edge, at most the narrower strip (0 = sharp edges).")
          .def("0 um").non_negative().affects(A::electric),
  };
}

} // namespace magbrush::case_keys
