// Case keys of module "measurements" (the list of modules and why it is explicit: case_keys.h).
// The DEM measurements: the development-nip profiles (nip) and Kawamoto's compression test
// (compression). Read by dem/measurements/.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> measurement_keys()
{
  return {
      section("nip", "Development-nip measurements (a scene with sleeve and drum): profiles along the gap of the beads "
                     "touching the drum, chain inclination, bead counts (docs/nip.md)."),
      quantity("nip.average_from", D::time, "Time-average the nip profiles over the samples at t >= this (the steady state).")
          .def("0 s").non_negative(),
      quantity("nip.sample_interval", D::time, "Time between samples of the nip measurements.").def("2 us").positive(),
      quantity("nip.bin_width", D::length, "Bin width along the nip (x: distance from the gap centre along the common tangent).")
          .def("0.25 mm").positive(),
      quantity("nip.half_width", D::length, "The drum profiles cover -half_width <= x <= half_width.").def("4 mm").positive(),
      quantity("nip.chain_bin_angle", D::angle, "Bin width of the chain-inclination profile in sleeve angle.")
          .def("2 deg").positive(),
      quantity("nip.chain_half_angle", D::angle, "The chain-inclination profile covers sleeve angles within this of the gap centre.")
          .def("30 deg").positive().max(180.0 * pi / 180.0),

      section("development", "Toner development onto the drum (a nip scene with a nip field and toner): toner mass "
                             "per area on the image and the background after the nip, developed q/m, "
                             "neutralisation of the latent image, where toner transfers (docs/development.md)."),
      quantity("development.measure_from", D::length, "The measuring window starts at this nip coordinate x "
                                                      "(downstream of the gap centre, past the brush).")
          .def("1 mm"),
      quantity("development.measure_to", D::length, "The measuring window ends at this nip coordinate x.").def("4 mm"),
      quantity("development.sample_interval", D::time, "Time between samples of the toner on the drum.")
          .def("2 us").positive(),
      quantity("development.average_from", D::time, "Sample from this time on (after the transient).")
          .def("0 s").non_negative(),
      choice("development.average_over", {"samples", "image_periods"},
             "samples: the means average the measuring window's samples (a scene whose image does not pass "
             "through the window: a development cell); image_periods: each drum element is counted once as it "
             "crosses measure_to, with the toner it carries then, and the means are over whole periods of the "
             "latent image (its blocks for the standard error and the steady-state test): a moving image's TMA "
             "repeats with its period in any fixed window; on a uniform image the blocks are development.block_length.")
          .def("samples"),
      integer("development.phase_bins", "Bins per latent-image period of the developed profile "
                                        "(toner_developed_profile.csv; image_periods only).")
          .def("40").min(1).max(100000),
      quantity("development.block_length", D::length,
               "With image_periods on a uniform image (a solid area: electric.image.duty 1; or a dark drum), "
               "which has no period: the drum length past measure_to that makes one block of the means "
               "(0: the image period).")
          .def("0 m").non_negative(),

      section("dma", "The developer on the sleeve after the doctor blade (a roller scene with a doctor blade): "
                     "developer mass per area (DMA) in a window past the blade and from the flux through it, the "
                     "blade's load, the developer held in front of the blade, the fraction released "
                     "(docs/regulation.md)."),
      quantity("dma.after_blade", D::angle, "The DMA window is centred this far past the doctor blade's tip, in the "
                                            "direction the sleeve turns; the flux is counted through its centre line.")
          .def("10 deg").positive().max(pi),
      quantity("dma.window", D::angle, "Angular width of the DMA window.").def("10 deg").positive().max(pi),
      quantity("dma.height", D::length, "Only particles within this distance of the sleeve surface count (the "
                                        "layer the sleeve carries).")
          .def("2 mm").positive(),
      quantity("dma.front_window", D::angle, "The developer held in front of the blade is weighed in this sector "
                                             "just before its tip.")
          .def("20 deg").positive().max(pi),
      quantity("dma.release_from", D::angle, "Release: a radial line before the release sector (roller angle); "
                                             "equal to dma.release_to: not measured.")
          .def("0 deg").min(-2.0 * pi).max(2.0 * pi),
      quantity("dma.release_to", D::angle, "Release: a radial line after it; the released fraction is "
                                           "1 - (flux after) / (flux before), near the sleeve.")
          .def("0 deg").min(-2.0 * pi).max(2.0 * pi),
      quantity("dma.sample_interval", D::time, "Time between samples.").def("10 us").positive(),
      quantity("dma.average_from", D::time, "Sample from this time on (after the transient).").def("0 s").non_negative(),

      section("statistics", "How a run's measured means are judged (every measurement's summary, dem/summary.csv): "
                            "standard errors by block averaging, steady state by the drift between halves."),
      number("statistics.steady_drift", "A mean counts as steady when the means of the two halves of its averaging "
                                        "window differ by less than this fraction of it.")
          .def("0.02").positive().max(1.0),
      integer("statistics.blocks", "Contiguous blocks of the standard error by block averaging (each should be much "
                                   "longer than the correlation time of the samples).")
          .def("10").min(2),

      section("compression", "Kawamoto's compression test: the plate measurement of a box scene with a moving "
                             "plate and a stage (forces, touching beads, chain spacing, contact maps; docs/compression_study.md)."),
      text("compression.plate", "Name of the moving plane wall (the pseudo-photoreceptor plate).").def("plate"),
      text("compression.stage", "Name of the plane wall the brush stands on.").def("stage"),
      quantity("compression.sample_interval", D::time, "Time between samples of the beads touching the plate.")
          .def("1 us").positive(),
      quantity("compression.average_window", D::time, "One output row is the mean of the samples in this window.")
          .def("20 us").positive(),
      quantity("compression.map_interval", D::time, "Time between per-bead contact maps (0 = one map at the end).")
          .def("0 s").non_negative(),
  };
}

} // namespace magbrush::case_keys
