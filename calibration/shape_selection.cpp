// The shared-or-per-pole choice of the pole fit's shape model (see shape_selection.h).
#include "calibration/shape_selection.h"

#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace {

PoleFitResult fit_with_shape(const Roller &nominal, const FluxScan &scan, double probe_radius,
                             PoleFitOptions options, PoleFitOptions::Shape shape)
{
  options.shape = shape;
  return fit_poles(nominal, scan, probe_radius, options);
}

double residual_sum_of_squares(const PoleFitResult &fit)
{
  return fit.rms * fit.rms * double(fit.samples);
}

std::string in_words(const ShapeSelection &s, bool per_pole_kept)
{
  std::ostringstream out;
  out.precision(3);
  out << "one shape factor per pole lowers the residual RMS from " << s.rms_shared * 1e3
      << " to " << s.rms_per_pole * 1e3 << " mT: F = " << s.test.F << " with ("
      << s.test.numerator_dof << ", " << s.test.denominator_dof << ") degrees of freedom, p = "
      << s.test.p_value << (per_pole_kept ? " < " : " ≥ ") << s.significance
      << (per_pole_kept ? ": significant, per-pole kept"
                        : ": not significant, the shared shape factor kept");
  return out.str();
}

} // namespace

PoleFitResult fit_poles_choosing_shape(const Roller &nominal, const FluxScan &scan,
                                       double probe_radius, const PoleFitOptions &options)
{
  PoleFitResult shared =
      fit_with_shape(nominal, scan, probe_radius, options, PoleFitOptions::Shape::shared);
  ShapeSelection s;
  s.automatic = true;
  s.significance = options.shape_significance;
  s.rms_shared = shared.rms;
  if (nominal.poles.size() < 2) // one pole: shared and per-pole are the same model
  {
    s.reason = "a single pole: its own shape factor";
    shared.shape_selection = s;
    return shared;
  }

  PoleFitResult per_pole;
  try
  {
    per_pole = fit_with_shape(nominal, scan, probe_radius, options, PoleFitOptions::Shape::per_pole);
  }
  catch (const std::invalid_argument &e) // e.g. too few values for the extra parameters
  {
    s.reason = std::string("one shape factor per pole could not be fitted (") + e.what() +
               "); the shared shape factor kept";
    shared.shape_selection = s;
    return shared;
  }
  s.rms_per_pole = per_pole.rms;
  s.test = compare_nested_models(residual_sum_of_squares(shared), shared.parameters,
                                 residual_sum_of_squares(per_pole), per_pole.parameters,
                                 shared.samples);
  // A per-pole fit that stopped without converging is no evidence for it.
  const bool keep_per_pole = per_pole.converged && s.test.p_value < s.significance;
  s.reason = per_pole.converged ? in_words(s, keep_per_pole)
                                : "the fit with one shape factor per pole did not converge (" +
                                      per_pole.status + "); the shared shape factor kept";
  PoleFitResult &chosen = keep_per_pole ? per_pole : shared;
  chosen.shape_selection = s;
  return chosen;
}

} // namespace magbrush
