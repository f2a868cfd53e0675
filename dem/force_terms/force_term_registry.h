// Which forces a step adds beyond the contacts is decided by the scene, in one place: every
// force term lives in its own file of dem/force_terms/ and registers a factory at start-up
// (like the measurements and the driver's subcommands):
//
//   const bool registered = register_force_term(
//       {"gravity", force_term_order::gravity,
//        [](const Case &c) -> std::string { return is_zero(c.dem.gravity) ? "dem.gravity is zero" : ""; },
//        [](const Case &c, const DemSystem &) { return std::make_unique<Gravity>(c.dem.gravity); }});
//
// The factory says itself whether the scene needs the term (no applied field: no magnetics;
// no charges: no electrostatics) and why not, so "skip what a scene doesn't need" is one rule
// per term and the run log lists every term with its state. Adding a term is one new file plus
// its case keys; dem_run.cpp and dem_main.cpp never change.
#pragma once

#include "dem/force_term.h"

#include "case/case_model.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

class DemSystem;

// The order in which the terms add their forces to a particle, the order of the papers' force
// list (Kawamoto A1: gravity and drag, then the magnetic force of A8–A11; Kweon eq. 1–6 adds
// the electric force qE of the nip field, Coulomb between the charges and the charges' images
// in the drum and the sleeve). It is fixed here,
// not left to the order of static initialisation, because floating-point sums depend on it: a
// run must give the same bits whatever the link order. Terms that run inside the engine's
// OpenMP team (ForceTerm::runs_in_team) must come before the others. A new term takes a slot
// here.
namespace force_term_order {
constexpr int gravity = 10;
constexpr int stokes_drag = 20;
constexpr int magnetic_dipoles = 30;
constexpr int electric_field = 40;   // qE in the stored nip field
constexpr int coulomb = 50;          // charge–charge, with the periodic images of the slab
constexpr int conductor_images = 60; // a charge's images in the drum (through its layer) and sleeve
} // namespace force_term_order

struct ForceTermFactory
{
  std::string name;
  int order = 0; // a force_term_order slot
  // "" when the scene needs the term, otherwise why not (for the log: "no applied field").
  std::function<std::string(const Case &)> not_needed_because;
  // The term for this case and engine (walls, periodic box, particles inserted or not).
  std::function<std::unique_ptr<ForceTerm>(const Case &, const DemSystem &)> make;
};

bool register_force_term(const ForceTermFactory &factory);
// Every registered factory, in force_term_order.
std::vector<ForceTermFactory> force_term_factories();

// What add_case_force_terms decided for one registered term.
struct ForceTermChoice
{
  std::string name;
  bool on = false;
  std::string reason; // why it is off ("" when on)
};

// Adds to `system` every registered term the case needs, in force_term_order; returns the
// decision for every registered term (on, or off with the reason).
std::vector<ForceTermChoice> add_case_force_terms(DemSystem &system, const Case &c);

} // namespace magbrush::dem
