// Choosing the shape model of the pole fit from the scan: one Gaussian shape factor α shared by
// all poles, or one per pole.
//
// A shared α is the simpler model and the better default when the poles really are alike (each
// α is then determined by all of the scan). But rollers are often magnetised pole by pole, with
// different widths, and a shared α then leaves a residual far above the noise and biases the
// strengths and angles. So both are fitted, from the same starting point, and the F-test for
// nested models (nested_model_test.h) decides: per-pole is kept when its lower residual has a
// p-value below PoleFitOptions::shape_significance (0.001 by default: one chance in a thousand
// that noise alone would lower the residual this much). The per-pole model has P − 1 more
// parameters than the shared one.
//
// Either way the chosen fit is judged against the scan's own noise (residual_warning in
// pole_fit.h): the F-test only says which of the two fits better, not that either is right.
#pragma once

#include "calibration/pole_fit.h"

namespace magbrush {

// Fits with Shape::shared and Shape::per_pole (the other options as given) and returns the one
// the F-test picks, with result.shape_selection saying why.
PoleFitResult fit_poles_choosing_shape(const Roller &nominal, const FluxScan &scan,
                                       double probe_radius, const PoleFitOptions &options);

} // namespace magbrush
