// Case keys of module "measurements" (the list of modules and why it is explicit: case_keys.h).
// The DEM measurements: the development-nip profiles (nip) and Kawamoto's compression test
// (compression). Read by dem/measurements/.
#include "coupling/case_keys.h"

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
