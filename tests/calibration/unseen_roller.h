// The roller of the pole-fit tests on unseen scans (test_unseen_scan, test_fe_scan): not the
// example roller the other flux tests use. Six poles at irregular angles on a 12 mm magnet
// around a 4 mm air core (μ_r = 1 everywhere, so that its field is exactly that of its
// magnetic charges), a probe at 13 mm; the design poles the fit starts from, and the true
// poles that make the scans.
#pragma once

#include "calibration/pole_fit.h"
#include "case/case_model.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace magbrush::unseen {

constexpr double deg = M_PI / 180.0;
constexpr double probe_radius = 13e-3;
constexpr double noise_sigma = 0.5e-3;       // [T] on each component
constexpr double encoder_offset = 3.7 * deg; // roller angle = scan angle + this

inline double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

// The roller of these tests with the design (nominal) poles the fit starts from: six poles at
// irregular angles, round strengths, α = 10. Air core (μ_r = 1) so the charge model is exact.
inline Roller design_roller()
{
  Roller r;
  r.shaft_radius = 4e-3;
  r.shaft_mu_r = 1.0;
  r.magnet_radius = 12e-3;
  r.magnet_mu_r = 1.0;
  r.poles = {{"N1", 10 * deg, 200e3, 10},  {"S1", 70 * deg, -200e3, 10},
             {"N2", 135 * deg, 200e3, 10}, {"S2", 190 * deg, -200e3, 10},
             {"N3", 250 * deg, 200e3, 10}, {"S3", 310 * deg, -200e3, 10}};
  return r;
}

// The roller that made the scan: the design angles with deviations summing to zero (so that
// the whole common rotation is the encoder offset, as the fit defines it), other strengths,
// and the given shape factors.
inline Roller true_roller(const std::vector<double> &alpha)
{
  Roller r = design_roller();
  const double deviation_deg[] = {+1.2, -0.8, +0.5, -1.5, +0.9, -0.3};
  const double strength[] = {250e3, -180e3, 210e3, -300e3, 160e3, -220e3};
  for (size_t i = 0; i < r.poles.size(); ++i)
  {
    r.poles[i].angle += deviation_deg[i] * deg;
    r.poles[i].strength = strength[i];
    r.poles[i].shape_factor = alpha[i];
  }
  return r;
}

inline const std::vector<double> per_pole_alpha{6, 14, 9, 20, 11, 8};
inline const std::vector<double> shared_alpha(6, 12.0);

// The largest deviation of the fitted poles from the true ones: angle [rad], strength and
// shape factor (relative).
struct Worst
{
  double angle = 0, strength = 0, shape = 0;
};

inline Worst worst_deviation(const PoleFitResult &fit, const Roller &truth)
{
  Worst w;
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    const Pole &f = fit.poles[i].pole, &t = truth.poles[i];
    w.angle = std::max(w.angle, std::abs(wrap_pm_pi(f.angle - t.angle)));
    w.strength = std::max(w.strength, std::abs(f.strength / t.strength - 1.0));
    w.shape = std::max(w.shape, std::abs(f.shape_factor / t.shape_factor - 1.0));
  }
  return w;
}

// The comparison's RMS over both components, in the fit's measure.
inline double combined_rms(const FluxComparison &c)
{
  return std::sqrt(0.5 * (c.Bn.rms * c.Bn.rms + c.Bt.rms * c.Bt.rms));
}

} // namespace magbrush::unseen
