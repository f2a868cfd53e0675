// How noisy is a gaussmeter scan? An estimate from the scan alone, so that a fit's residual
// can be judged against it ("is what is left over just noise, or is the model wrong?").
//
// The method: a sleeve flux profile is smooth on the scale of the sampling (a pole is tens of
// degrees wide, a scan samples every degree or finer), so each sample is compared with the
// cubic through its two neighbours on either side. For the smooth profile that prediction is
// almost exact (on the noise-free scan of tests/calibration/test_unseen_scan, 0.5° steps and
// α up to 20, the profile leaks 3e-5 mT into the estimate, against a 94 mT peak); what is
// left is a fixed combination of five noise values. For evenly
// spaced samples it is the fourth difference / 6, whose standard deviation is
// σ·√(1 + 2/36 + 2·16/36) = σ·√(70/36); for uneven spacing each sample's own Lagrange weights
// give its factor. The noise σ is then the median of |difference| / factor divided by 0.6745
// (the median of |x| for a unit normal), so a few spikes or a sharp feature do not inflate it.
//
// Assumes independent noise from sample to sample; noise correlated over neighbouring samples
// (a probe that averages over several degrees) is underestimated.
#pragma once

#include "calibration/flux_scan.h"

#include <cstddef>
#include <vector>

namespace magbrush {

struct ScanNoise
{
  double Bn = 0.0;       // estimated standard deviation of the Bn noise [T]
  double Bt = 0.0;       // of the Bt noise [T] (0 when the scan has no Bt)
  std::size_t samples = 0; // how many samples the estimate rests on (per component)
};

// The noise of one component sampled at `angle` (strictly monotone, any spacing). 0 with
// fewer than 5 samples.
double estimate_noise(const std::vector<double> &angle, const std::vector<double> &value);

ScanNoise estimate_scan_noise(const FluxScan &scan);

} // namespace magbrush
