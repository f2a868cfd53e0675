// Case keys of module "magnetics" (the list of modules and why it is explicit: case_keys.h).
// The carrier magnetics: every dem.magnetic_* key. Read by magnetics/magnetic_settings
// (MagneticSettings::from_case), which also takes dem.verlet_skin (declared by the DEM) for its
// own lists unless dem.magnetic_skin sets theirs.
//
// These defaults are what a user's case runs. MagneticSettings' member initialisers (the
// settings a test or a bench builds by hand) must equal them: tests/case/test_module_defaults
// fails when they disagree.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> magnetic_keys()
{
  return {
      choice("dem.magnetic_model", {"point_dipole", "mutual_dipole", "corrected"},
             "Carrier magnetics: fixed point dipoles, mutual induction, or mutual + exact two-sphere correction.")
          .def("corrected"),
      number("dem.magnetic_cutoff", "Hard cutoff radius in mean carrier diameters, used only with magnetic_far_field: none (12: ~1 % force error in a brush with the slab tail, 5 % in the nip slab, docs/magnetics.md; the papers used 4).").def("12").positive(),
      quantity("dem.magnetic_refresh", D::time, "Magnetic force refresh interval (0 = every step).").def("0 s").non_negative(),
      number("dem.magnetic_tolerance", "Mutual-induction relative tolerance (1e-4: force error ~1e-5, docs/magnetics.md).").def("1e-4").positive(),
      choice("dem.magnetic_far_field", {"none", "cell_multipole"},
             "Magnetic far field: cell_multipole (no cutoff: exact pairs within 2 fine cells, the whole rest of the domain and every periodic image by cell multipoles, docs/magnetics.md) or none (hard cutoff at magnetic_cutoff).")
          .def("cell_multipole"),
      integer("dem.magnetic_far_order", "Taylor order of the cell multipoles (error vs cost in docs/magnetics.md).").def("2").non_negative().max(6),
      number("dem.magnetic_staleness", "Refresh the magnetic forces early when some carrier moved more than this fraction of its radius since the last refresh (held-force error ~0.37 x this, RMS, at the refresh; half of it on average, docs/magnetics.md).").def("0.05").positive(),
      choice("dem.magnetic_staleness_mode", {"relative", "local", "absolute"},
             "What makes held magnetic forces stale before magnetic_refresh elapses, and what it triggers: relative (a pair closer than 4 radii whose vector changed by magnetic_staleness x its mean radius, or a carrier that moved 5 x magnetic_staleness x its radius in the applied field: a local refresh around them; a rigidly carried brush triggers nothing), local (a carrier that moved magnetic_staleness x its radius: a local refresh around it) or absolute (the same trigger, a full refresh: the behaviour before; docs/magnetics.md).")
          .def("relative"),
      choice("dem.magnetic_hold", {"forces", "dipoles"},
             "What the magnetics hold between evaluations: forces (each carrier's magnetic force as last evaluated) or dipoles (the dipoles and local fields; the forces of the pairs within 3 mean radii follow the beads, evaluated every 20 steps from the held dipoles). Holding dipoles is the more accurate for a given magnetic_staleness and magnetic_refresh, so both can be larger (flowing nip at 0.2 and 20 us: 0.27 % RMS held-force error against 1.07 % holding forces; docs/magnetics.md).")
          .def("forces"),
      number("dem.magnetic_skin", "Skin of the magnetic lists (the far field's cells and near pairs, the two-sphere correction's pairs) in mean carrier diameters; they are rebuilt, with a full evaluation, when a carrier moved half of it (0 = dem.verlet_skin, the contact list's). A larger skin means fewer rebuilds in a flowing brush but longer correction lists (the placed quick nip: 1 diameter with magnetic_staleness 0.6 and magnetic_refresh 40 us; the fed nip, the default case: 2 diameters with 0.4 and 30 us; docs/magnetics.md).").def("0").non_negative().max(10.0),
      integer("dem.magnetic_live_steps", "With magnetic_hold: dipoles, the close pairs' forces follow the beads every this many steps (held in between).").def("20").positive().max(1000),
      number("dem.magnetic_far_cell", "Fine cell size of the magnetic far field in mean carrier diameters (1.5 with order 2: 0.6 % RMS force error on an open brush, 1.1 % on a periodic strip, against brute-force sums; docs/verification.md).").def("1.5").positive().max(10.0),
  };
}

} // namespace magbrush::case_keys
