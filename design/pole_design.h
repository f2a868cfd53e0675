// The pole layout that meets a target: bounded nonlinear least squares on the exact ring.
//
// Unknowns: each free pole's angle φ_i and strength |M_i| (its sign, N or S, and its shape
// factor stay the case's). Each lies in a box (design_target.h, DesignConstraints); the box is
// built into the parametrisation, p = low + (high − low)(1 + sin u)/2, so that Eigen's
// Levenberg–Marquardt (the pole fit's solver) works on an unbounded u and every iterate is a
// feasible layout. The residuals are the requirements' (design_requirements.h), each scaled
// by its tolerance, plus a faint pull towards the case's layout, λ (Δφ/1° and Δ|M|/(1 % of
// |M|)) with λ = 1e-3 by default: it makes an under-determined target (a spec naming two poles
// of five) pick the layout nearest the case, and moves a determined one by far less than any
// tolerance. The Jacobian is by central differences (the peak requirements are computed
// quantities, not closed-form).
//
// The least squares is not convex (poles trade places, a peak can be made by two neighbours),
// so it runs from several starts: the case's layout, then layouts drawn uniformly in the boxes
// (a fixed seed: the same run gives the same answer). The best is kept.
//
// A layout misses a requirement when no layout in the boxes meets it: the result is then
// infeasible and says which bounds bind — a parameter at its bound whose cost would fall
// beyond it, a fixed pole that would move if it could, the minimum spacing at its limit.
#pragma once

#include "design/design_requirements.h"
#include "design/design_target.h"

#include <string>
#include <vector>

namespace magbrush {

struct DesignOptions
{
  int starts = 8;              // the case's layout + starts − 1 random ones
  unsigned seed = 55;
  int max_evaluations = 4000;  // per start
  double regularisation = 1e-3; // λ: the pull towards the case's layout
};

// One free unknown of the layout.
struct DesignParameter
{
  size_t pole = 0;
  bool angle = true;           // else the strength magnitude |M|
  double low = 0, high = 0;    // [rad] or [A/m]
  bool high_is_remanence_limit = false;
  std::string name(const std::vector<Pole> &poles) const; // "S2 angle", "S2 |M|"
};

struct DesignResult
{
  std::vector<Pole> poles;                    // the best layout found
  std::vector<DesignParameter> parameters;    // the free unknowns and their boxes
  std::vector<RequirementResult> requirements; // of the best layout, on the exact ring
  double cost = 0;             // Σ of the requirements' squared residuals
  bool feasible = false;       // every requirement met
  std::vector<std::string> binding; // the constraints that bind, in words
  std::vector<double> start_costs;
  int best_start = 0, starts_at_best = 0; // starts that reached the best cost (within 1e-6)
  long evaluations = 0;
  std::string status;          // LM's verdict on the best start
  int harmonics = 0;
};

DesignResult design_poles(const Roller &roller, double probe_radius, const DesignTarget &target,
                          const DesignConstraints &constraints, const DesignOptions &options = {});

} // namespace magbrush
