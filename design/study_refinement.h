// The active study: where one more point of a finished study narrows the answer of its inverse
// (study_inverse.h) the most.
//
// A point not yet run is known only by what the study predicts for it: its mean from the
// study's own interpolation (the bracketing piece, or the weighted line where the inverse uses
// the line), its standard error from its neighbours' (linear in x between the two points that
// bracket it; the mean of all points' for the line). Each candidate is added to the table as
// such a predicted point and the inverse is taken again; the candidate whose answer has the
// smallest standard error is the one to run. Since the predicted mean lies on the study's own
// curve the answer stays where it is and only its error changes, so the choice needs no DEM.
//
// For the piecewise inverse with bracket (x_i, x_{i+1}) and a new point c between them the
// answer's error becomes |Δx/Δy| · hypot((1 − t)σ_c, t σ_j) over the new, shorter piece, so
// the best c lies near the answer itself — a little towards the better-known neighbour (at
// t = σ_c²/(σ_c² + σ_j²)). A point of the same length as its neighbours cannot beat their
// mean, so once the answer sits between two points of similar error more points hardly help:
// its error is set by the runs' own (~σ/|slope|), and only longer runs or repeats narrow it. `gain` says how much the best candidate is predicted to narrow the answer; the
// caller stops when it is small.
#pragma once

#include "design/study_inverse.h"

namespace magbrush {

struct RefinementPlan
{
  double x = 0;             // the point to run [SI]
  double predicted_y = 0;   // what the study predicts there
  double predicted_se = 0;  // the standard error expected of its run
  double se_now = 0;        // the answer's standard error now
  double se_after = 0;      // and with the point added as predicted
  double gain() const { return se_now > 0 ? 1.0 - se_after / se_now : 0.0; }
};

// `candidates` points evenly over the bracket of the answer (piecewise) or over the study's
// range (line). Throws when the target lies outside the study (an extrapolation is not
// narrowed by a point inside it: extend the study instead).
RefinementPlan plan_refinement(const StudyTable &table, double target,
                               StudyAnswer::Method method = StudyAnswer::Method::automatic,
                               int candidates = 201);

} // namespace magbrush
