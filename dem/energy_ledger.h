// The energy balance of a run, kept step by step:
//
//   work of the moving walls on the particles + work of the fields
//       = Δ(kinetic + rotational) + Δ(elastic energy of the contacts) + Δ(gravitational
//         potential) + energy dissipated in the contacts.
//
// The engine itself keeps no energy account (its guard watches only the kinetic energy's
// growth, stability_guards.h). The ledger is a diagnostic that watches a DemSystem from
// outside, after every step: it recomputes each touching contact from the state (the same
// contact law, contact_law.h, with the half-step velocities the step's force evaluation saw)
// and sums over the steps
//   * the work of the normal dashpots on the particles' relative motion, with f_d the
//     dashpot's share of the normal force after the "no pulling" clamp (f_n = max(0, F_Hertz
//     + c_n v_rel·n)), in the form velocity Verlet's kinetic energy obeys exactly (record());
//   * the work each moving wall puts in, F_wall→particle · v_surface at the contact point
//     (trapezoid rule).
// The gravitational potential −Σ m g·x and the Hertz energies (2/5) k_n δ^{5/2} of particle
// pairs and wall contacts are state functions, taken at the ends. What is left over, the
// residual, is the integration's own energy error plus the trapezoid rule's.
//
// It accounts for what frictionless, non-adhesive contacts do under gravity: a scene with
// friction, rolling friction, adhesion or a force term other than gravity (drag, magnetics,
// charges) is refused with what it cannot account for, rather than balanced wrongly. (The
// tangential Mindlin spring's stored energy and its slip losses, with a stiffness that changes
// with δ, would need their own bookkeeping.)
#pragma once

#include "dem/dem_system.h"

#include <vector>

namespace magbrush::dem {

class EnergyLedger
{
public:
  // Starts the account at the system's present state (after initialize() or a settle).
  explicit EnergyLedger(const DemSystem &system);

  // Call after every step (advance(1)): adds this step's dissipation and wall work.
  void record(const DemSystem &system);

  struct Balance
  {
    double kinetic = 0;       // translational + rotational now [J]
    double elastic = 0;       // Hertz energy of every touching contact now [J]
    double gravitational = 0; // −Σ m g·x now [J]
    double dissipated = 0;    // by the contacts since the start [J]
    double wall_work = 0;     // by the walls on the particles since the start [J]
    double initial = 0;       // kinetic + elastic + gravitational at the start [J]
    // wall work − (Δ(kinetic + elastic + gravitational) + dissipated) [J]
    double residual() const { return wall_work - (kinetic + elastic + gravitational - initial + dissipated); }
  };
  Balance balance(const DemSystem &system) const;

private:
  // What the ledger needs of one state: per particle id (the index changes when the engine
  // re-sorts) its velocity and the dashpots' total force on it; the walls' power and the part
  // of it their dashpots take; the contacts' elastic energy.
  struct Forces
  {
    std::vector<Vector3> dashpot, velocity;
    std::vector<char> present;
    double wall_power = 0.0, dashpot_wall_power = 0.0, elastic = 0.0;
  };
  static Forces forces(const DemSystem &system);
  static double potential(const DemSystem &system);
  Forces last_;
  double last_time_ = 0.0;
  double dissipated_ = 0.0, wall_work_ = 0.0, initial_ = 0.0;
};

} // namespace magbrush::dem
