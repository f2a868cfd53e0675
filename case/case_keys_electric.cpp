// Case keys of module "electric" (the list of modules and why it is explicit: case_keys.h).
// Nip electrostatics: sleeve bias and latent image. Read by the field solver's electrostatic
// problem (field_solver/).
#include "case/case_keys.h"

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
      quantity("electric.image.period", D::length, "Strip period along the drum surface (0 = uniform: dark, or exposed everywhere at duty 1).")
          .def("0 mm").non_negative().affects(A::electric),
      number("electric.image.duty", "Exposed fraction of one period; 1 = a solid exposed area (a TMA patch), 0 = dark everywhere.").def("0.5").min(0.0).max(1.0).affects(A::electric),
      // Coulomb and the conductors' images (DEM only: dem/force_terms/coulomb, conductor_images).
      boolean("electric.coulomb",
              "Coulomb forces between the charged particles, without a cutoff, over the periodic images of the slab (on when some population is charged).")
          .def("true"),
      integer("electric.coulomb_order",
              "Taylor order of the Coulomb far field (force error against cost: docs/electrostatics.md).")
          .def("4").non_negative().max(6),
      quantity("electric.coulomb_cell", D::length,
               "Fine cell size of the Coulomb far field; pairs within two cells are summed exactly (25 um: ~30 exact partners per charge in a toner-laden nip, docs/electrostatics.md).")
          .def("25 um").positive(),
      quantity("electric.coulomb_refresh", D::time,
               "Interval between evaluations of the Coulomb far field, held in between (0 = every step); the near pairs are exact at every step (2 us: ~1e-3 RMS force error at 0.1 m/s relative motion, docs/electrostatics.md).")
          .def("2 us").non_negative(),
      boolean("electric.conductor_images",
              "The charges' images in the grounded drum substrate (through the photoconductor layer) and in the sleeve. false = Kweon's assumption that the field is unchanged by the toner (no screening by the conductors).")
          .def("true"),
      integer("electric.pair_image_terms",
              "Drum images per charge that act on the OTHER charges (explicit terms of the layered image series, the rest lumped keeping charge and dipole moment; 0 = the self force only).")
          .def("2").non_negative().max(20),
      quantity("electric.hold_distance", D::length,
               "The electric forces (qE, Coulomb, images) are evaluated again when some particle or the latent image has moved this far since their last evaluation, and held in between (0 = every step). 20 nm: force error against cost in docs/electrostatics.md.")
          .def("20 nm").non_negative(),
      choice("electric.coulomb_hold_frame", {"lab", "sleeve"},
             "The frame in which the Coulomb term's moves are measured against electric.hold_distance: lab, or sleeve (the frame turning with the sleeve: a developer riding it changes no pair and renews nothing; docs/electrostatics.md).")
          .def("lab"),
      quantity("electric.image.edge_width", D::length, "Width of the smooth (raised-cosine) transition at each strip edge, at most the narrower strip (0 = sharp edges).")
          .def("0 um").non_negative().affects(A::electric),
  };
}

} // namespace magbrush::case_keys
