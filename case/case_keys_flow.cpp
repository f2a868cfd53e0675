// Case keys of module "flow" (the list of modules and why it is explicit: case_keys.h).
// Particles entering and leaving a roller scene: developer fed onto the sleeve upstream
// (inflow), removed downstream (outflow), and the flow report (counts and masses in, out and
// present; the flux through a radial line and the areal mass around it). Read by
// dem/particle_source, dem/particle_sink, dem/particle_flow and dem/measurements/flow_report.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> flow_keys()
{
  return {
      section("inflow", "Developer fed onto the sleeve during the run: a layer of the given mass per area created "
                        "just downstream of an entry angle, moving with the sleeve, so that the mass flux is "
                        "areal_mass x sleeve speed x slab length (docs/design.md, particles entering and leaving)."),
      text("inflow.population", "The carrier population fed (\"\" = the first carrier population). Toner populations "
                                "with a concentration come attached to the carriers in that proportion.")
          .def(""),
      quantity("inflow.areal_mass", D::areal_mass,
               "Developer (carrier + toner) mass per sleeve area carried in (DMA; 0 = no inflow).")
          .def("0 kg/m^2").non_negative(),
      quantity("inflow.angle", D::angle, "Entry angle on the sleeve (roller angle, counter-clockwise from +x): new "
                                         "particles appear in the arc the sleeve surface swept past it since the last exchange.")
          .def("0 deg").min(-2.0 * pi).max(2.0 * pi),
      quantity("inflow.layer_height", D::length, "New particles are placed within this distance of the sleeve surface "
                                                 "(at random, without overlap).")
          .def("0.5 mm").positive(),
      choice("inflow.supply", {"fixed", "sump"},
             "fixed: exactly areal_mass is fed, and a run whose entry arc has no room for it stops with an error; "
             "sump: the inflow stands for a sump that offers areal_mass, and what finds no room in the entry arc "
             "(a pile backed up from a doctor blade) stays in the sump: the mass picked up is then measured, not set.")
          .def("fixed"),
      quantity("inflow.prefill_arc", D::angle,
               "At the start the sleeve already carries the fed layer (areal_mass, placed as the inflow places it) "
               "over this arc downstream of inflow.angle, as if it had turned for a while: the run does not spend "
               "a transit time bringing the first developer to the nip or the blade (0 = the sleeve starts bare). "
               "These particles are part of the initial state; at rest when the scene settles first.")
          .def("0 deg").non_negative().max(2.0 * pi),
      choice("inflow.prefill_where_no_room", {"refuse", "thin"},
             "Where the prefilled layer finds no room (a drum nearer the sleeve than inflow.layer_height, at the "
             "layer's mass per area): refuse: the run stops with the angle where it does not fit; thin: what fits "
             "is placed there, and downstream the layer keeps only the fraction that passed its narrowest place, "
             "as a layer squeezed through a gap does (a nip filled from the start, instead of after a transit).")
          .def("refuse"),
      quantity("inflow.sump_mass", D::linear_mass,
               "With supply: sump, the developer in the sump per length along the roller axis (0 = unlimited). "
               "The inflow draws on it (carriers and toner, each from its own stock) and everything the outflow "
               "removes returns to it, so the developer in the scene and in the sump together stays constant over "
               "any number of revolutions.")
          .def("0 kg/m").non_negative(),
      quantity("inflow.interval", D::time, "Time between exchanges: insertions and removals happen every interval.")
          .def("1 us").positive(),

      section("outflow", "Particles removed during the run: those in a sector of the sleeve downstream, and those "
                         "that left the window around the sleeve."),
      quantity("outflow.angle", D::angle, "Start of the removal sector (roller angle); it extends from here in the "
                                          "direction the sleeve turns.")
          .def("0 deg").min(-2.0 * pi).max(2.0 * pi),
      quantity("outflow.width", D::angle, "Angular extent of the removal sector (0 = none).")
          .def("0 deg").non_negative().max(2.0 * pi),
      quantity("outflow.outer_radius", D::length, "Also remove particles farther than this from the roller axis (0 = none).")
          .def("0 mm").non_negative(),

      section("flow_report", "The flow report of a scene with inflow or outflow (flow_report.csv): particles and mass "
                             "in, out and present, the mass flux through a radial line and the areal mass around it."),
      quantity("flow_report.sample_interval", D::time, "Time between samples.").def("2 us").positive(),
      quantity("flow_report.flux_angle", D::angle, "The radial line (roller angle) through which the flux is counted.")
          .def("0 deg").min(-2.0 * pi).max(2.0 * pi),
      quantity("flow_report.density_window", D::angle, "Angular window centred on the flux line over which the areal "
                                                        "mass is measured.")
          .def("10 deg").positive().max(pi),
      quantity("flow_report.average_from", D::time,
               "The summary's means (summary.csv: the supplied flux and areal mass at the flux line, the "
               "fraction of a sump's offer declined) over the samples at t >= this (the steady state).")
          .def("0 s").non_negative(),
  };
}

} // namespace magbrush::case_keys
