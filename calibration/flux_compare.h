// Comparing a computed sleeve flux profile with a gaussmeter scan: RMS and maximum errors of
// Bn and Bt, and each pole's peak (angle and value) side by side.
//
// Both profiles are sampled at the scan's angles (the computed one is evaluated or
// interpolated there by the caller). A pole's peak is the extremum of Bn with the pole's sign
// nearest the pole's angle, within half the angular distance to its neighbours, refined by a
// least-squares parabola through the samples within ±3° of the largest one (robust to noise).
#pragma once

#include "calibration/flux_scan.h"
#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush {

struct PeakMatch
{
  bool found = false;
  double angle = 0.0; // [rad], in the frame of the angles given
  double value = 0.0; // [T]
};

// For each pole, the extremum of B of the pole's sign near (pole angle − offset) in the given
// angles' frame (i.e. the pole's angle seen in a scan whose roller-frame angle is θ + offset).
std::vector<PeakMatch> find_pole_peaks(const std::vector<Pole> &poles,
                                       const std::vector<double> &angle,
                                       const std::vector<double> &B, double offset = 0.0);

struct ComponentErrors
{
  double rms = 0.0, max = 0.0; // [T]
  double max_angle = 0.0;      // where |error| is largest [rad]
  double peak = 0.0;           // max |measured| [T], for relative figures
};

struct PolePeakComparison
{
  std::string pole;
  PeakMatch computed, measured;
};

struct FluxComparison
{
  std::vector<double> angle;               // scan angles [rad]
  std::vector<double> computed_Bn, computed_Bt, measured_Bn, measured_Bt; // [T]
  ComponentErrors Bn, Bt;                  // Bt only when the scan has it
  bool has_tangential = false;
  std::vector<PolePeakComparison> peaks;
  // Clear extrema of the measured Bn (above 20 % of its largest magnitude, the largest within
  // ±10°) that no pole of the case accounts for: a pole missing from the case, or a wrong sign.
  std::vector<PeakMatch> unmatched;
  // Correlation of measured and computed Bt (1 = same shape); strongly negative means the
  // scan's Bt has the opposite sign convention.
  double tangential_correlation = 0.0;
};

FluxComparison compare_flux(const FluxScan &scan, const std::vector<double> &computed_Bn,
                            const std::vector<double> &computed_Bt, const std::vector<Pole> &poles);

// Human-readable tables (mT, deg).
std::string format_errors(const FluxComparison &c);
std::string format_peaks(const FluxComparison &c);

// angle_deg, Bn/Bt measured and computed and residual (measured − computed), mT. Atomic write.
void write_residuals_csv(const std::string &path, const FluxComparison &c);

} // namespace magbrush
