// Case keys of module "particles" (the list of modules and why it is explicit: case_keys.h).
// The particles: materials (contact and bulk properties) and populations (sizes, amounts,
// where they are inserted). Read by the DEM (dem/contact_parameters, dem/insertion) and by the
// magnetics (the carrier's mu_r and saturation magnetisation).
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> particle_keys()
{
  return {
      map("materials", "Contact and bulk properties by name (carrier, toner, sleeve, drum, wall, ...)."),
      quantity("materials.*.youngs_modulus", D::pressure, "Young's modulus E.").required().positive(),
      number("materials.*.poisson_ratio", "Poisson's ratio.").def("0.3").min(-1.0, false).max(0.5, false),
      quantity("materials.*.density", D::density, "Density (particles; unused for walls).")
          .def("0 kg/m^3").non_negative(),
      number("materials.*.mu_r", "Relative permeability (carrier beads).").def("1").min(1.0),
      quantity("materials.*.saturation_magnetisation", D::magnetisation, "Saturation magnetisation (0 = linear).")
          .def("0 kA/m").non_negative(),
      number("materials.*.friction", "Sliding friction coefficient.").def("0").non_negative(),
      number("materials.*.rolling_friction", "Rolling friction coefficient (0 = from polygon_angles).")
          .def("0").non_negative(),
      integer("materials.*.polygon_angles", "Kawamoto's polygon rule for rolling resistance (0 = off, else >= 3).")
          .def("0").non_negative(),
      number("materials.*.damping", "Kawamoto's Voigt damping constant alpha.").def("0").non_negative(),
      number("materials.*.restitution", "Coefficient of restitution (LIGGGHTS form); -1 = unused.")
          .def("-1").min(-1.0).max(1.0),
      quantity("materials.*.hamaker", D::energy,
               "Hamaker constant A for van der Waals adhesion (pairs: sqrt(A1 A2) unless in adhesion_pairs; "
               "a material with A > 0 needs it written, 0 J included, for every material it touches).")
          .def("0 J").non_negative(),
      quantity("materials.*.adhesion_radius", D::length,
               "Asperity radius through which it touches, sets the adhesion force (0 = the particle radius; "
               "walls: 0 = flat).")
          .def("0 nm").non_negative(),

      list("populations", "Particle populations (carrier, toner)."),
      text("populations[].name", "Population name.").required(),
      choice("populations[].kind", {"carrier", "toner"}, "Particle kind.").def("carrier"),
      text("populations[].material", "Material (key in materials).").def("<kind>"),
      quantity("populations[].diameter", D::length, "Mean diameter.").required().positive(),
      quantity("populations[].diameter_std", D::length, "Standard deviation of the diameter (normal; truncated at ±3σ and at 5 % of the mean for particles made during a run: inflow, toner released from its carrier; at insertion to positive sizes).")
          .def("0 um").non_negative(),
      integer("populations[].count", "Number of particles (give exactly one of count, mass, concentration).")
          .def("0").non_negative(),
      quantity("populations[].mass", D::mass, "Total mass of the population.").def("0 kg").non_negative(),
      number("populations[].concentration", "Toner only: toner mass / carrier mass (e.g. 7 %).")
          .def("0").non_negative().max(1.0, false),
      quantity("populations[].charge_to_mass", D::charge_to_mass,
               "Mean charge-to-mass ratio q/m; each particle carries q = (q/m) m (toner: required).")
          .def("0 uC/g"),
      quantity("populations[].charge_to_mass_std", D::charge_to_mass,
               "Standard deviation of q/m between particles (normal, truncated so that it never flips the sign).")
          .def("0 uC/g").non_negative(),
      number("populations[].wrong_sign_fraction",
             "Fraction of the particles whose charge has the opposite sign to q/m (wrong-sign toner).")
          .def("0").min(0.0).max(1.0),
      boolean("populations[].counter_charge",
              "Carrier only: the carriers carry the opposite of the total charge of all other particles, "
              "shared by surface area, so that the developer is neutral.")
          .def("false"),
      boolean("populations[].attached",
              "Toner with a concentration only: placed touching the carriers' surfaces at random points, "
              "each carrier carrying the concentration times its own mass, as developer carries its toner "
              "(instead of at random in the insertion region).")
          .def("false"),
      quantity("populations[].carried_until_gap", D::length,
               "Toner on the carriers (attached, or fed by the inflow) only: the reduced toner model. Each "
               "carrier carries its toner as a count, mass and charge (part of its own) instead of as "
               "particles, until its surface comes this close to the drum surface; then the toner is placed "
               "touching it at random points as particles, which may develop; a toner particle touching a "
               "carrier farther than twice this from the drum becomes its carried toner again. 0 = the "
               "toner is always particles. Assumes no toner leaves a carrier farther from the drum.")
          .def("0 um").non_negative(),
      Key("populations[].insert_box", KeyType::box, "Insertion box [[xmin, ymin, zmin], [xmax, ymax, zmax]].")
          .dim(D::length),
      quantity("populations[].layer_thickness", D::length, "Insert as a layer of this thickness on the sleeve.")
          .def("0 mm").non_negative(),

      list("adhesion_pairs", "Hamaker constants of material pairs, overriding sqrt(A1 A2) (e.g. toner on the drum)."),
      text("adhesion_pairs[].material_a", "First material (key in materials).").required(),
      text("adhesion_pairs[].material_b", "Second material (key in materials; may equal the first).").required(),
      quantity("adhesion_pairs[].hamaker", D::energy, "Hamaker constant A12 of the pair (0 J = no adhesion).")
          .required().non_negative(),
  };
}

} // namespace magbrush::case_keys
