// Case keys of module "dem" (the list of modules and why it is explicit: case_keys.h).
// The DEM engine's run control: time step, duration, output and checkpoint intervals,
// periodicity, neighbour-list skin, drag, gravity, seed, threads, stability guards. Read by
// dem/ (dem_run, dem_system, time_step, contact_parameters, the force terms). The section also
// holds the magnetics' dem.magnetic_* keys, declared in case_keys_magnetics.cpp.
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> dem_keys()
{
  return {
      section("dem", "Discrete-element run control."),
      quantity("dem.time_step", D::time, "Time step (0 = automatic from the Rayleigh/Hertz criterion).").def("0 s").non_negative(),
      number("dem.time_step_safety", "Automatic step = this x Rayleigh time.").def("0.2").positive().max(1.0),
      quantity("dem.duration", D::time, "Simulated time.").def("0 s").non_negative(),
      boolean("dem.leg", "This run is the first leg of a longer one (a sweep's spin-up, a run continued with --resume "
                         "or --restart to a later dem.duration): its measurements' averaging windows may lie after its "
                         "end, which is otherwise refused. Run control: a continued run may drop it.")
          .def("false"),
      quantity("dem.output_interval", D::time, "Snapshot interval (0 = only at the end).").def("0 s").non_negative(),
      quantity("dem.checkpoint_interval", D::time,
               "Simulated time between checkpoints (0 = only at the end). Each one is written atomically and the one before it is kept (checkpoint.previous.bin); writing one changes nothing in the run (dem/README.md).")
          .def("250 us").non_negative(),
      quantity("dem.checkpoint_wall_interval", D::time,
               "Wall-clock time between checkpoints besides dem.checkpoint_interval (0 = none), so that a crash or a kill loses at most this much work; the results do not depend on it.")
          .def("10 min").non_negative(),
      quantity("dem.periodic_length", D::length, "Periodic slab length along the roller axis z (0 = none).").def("0 mm").non_negative(),
      quantity("dem.periodic_length_x", D::length, "Periodic length along x (0 = none).").def("0 mm").non_negative(),
      quantity("dem.periodic_length_y", D::length, "Periodic length along y (0 = none).").def("0 mm").non_negative(),
      number("dem.verlet_skin", "Neighbour-list skin as a fraction of the mean diameter.").def("0.3").positive(),
      quantity("dem.air_viscosity", D::viscosity, "Air viscosity for Stokes drag (0 = no drag).").def("1.81e-5 Pa*s").non_negative(),
      vector3("dem.gravity", D::acceleration, "Gravitational acceleration.").def("[0, -9.81 m/s^2, 0]"),
      integer("dem.seed", "Random seed (insertion, size distribution).").def("1").non_negative(),
      integer("dem.threads", "OpenMP threads (0 = default).").def("0").non_negative(),
      number("dem.max_overlap_fraction", "Stop when an overlap exceeds this fraction of a radius.").def("0.1").positive().max(1.0),
      choice("dem.restitution_model", {"ln_e", "hertz_exact"},
             "Materials with restitution: ln_e (LIGGGHTS/LAMMPS form) or hertz_exact (damping fitted to give e exactly).")
          .def("ln_e"),
      quantity("dem.settle_time", D::time, "After insertion, settle this long with the walls at rest.").def("0 s").non_negative(),
      number("dem.max_kinetic_energy_growth", "Stability guard: kinetic energy may not grow by more than this factor between checks.")
          .def("1000").min(1.0, false),
      quantity("dem.adhesion_cutoff", D::length,
               "Van der Waals adhesion: the gap z0 at which the force saturates (contact distance).")
          .def("0.4 nm").positive(),
      number("dem.adhesion_range_fraction",
             "Van der Waals adhesion is cut beyond the gap where it has fallen to this fraction of its contact value.")
          .def("0.01").positive().max(1.0, false),
      number("dem.toner_stiffness_factor",
             "Toner contacts use Young's modulus x this (a larger time step; see dem/README.md for its error).")
          .def("1").positive().max(1.0),
      integer("dem.toner_substeps",
              "Multiple time stepping: the toner (and every contact it takes part in) advances in this many substeps of "
              "the step, and the step is this many times the toner's stable step, within the carriers' own stable step "
              "(0 = as many substeps as that allows; 1 = one step for every particle). See dem/README.md.")
          .def("1").non_negative().max(64),
  };
}

} // namespace magbrush::case_keys
