// Noise of a scan from the scan itself (see scan_noise.h).
#include "calibration/scan_noise.h"

#include <algorithm>
#include <cmath>

namespace magbrush {

namespace {

// Weights of the cubic through (x[k−2], x[k−1], x[k+1], x[k+2]) evaluated at x[k]
// (Lagrange interpolation), in that order.
std::vector<double> cubic_prediction_weights(const std::vector<double> &x, std::size_t k)
{
  const double nodes[4] = {x[k - 2], x[k - 1], x[k + 1], x[k + 2]};
  std::vector<double> w(4, 1.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (j != i)
        w[i] *= (x[k] - nodes[j]) / (nodes[i] - nodes[j]);
  return w;
}

double median(std::vector<double> v)
{
  const auto middle = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

} // namespace

double estimate_noise(const std::vector<double> &angle, const std::vector<double> &value)
{
  if (angle.size() < 5)
    return 0.0;
  // |sample − prediction| in units of the noise's σ times its factor (see scan_noise.h).
  std::vector<double> scaled;
  for (std::size_t k = 2; k + 2 < angle.size(); ++k)
  {
    const auto w = cubic_prediction_weights(angle, k);
    const double predicted =
        w[0] * value[k - 2] + w[1] * value[k - 1] + w[2] * value[k + 1] + w[3] * value[k + 2];
    double factor2 = 1.0;
    for (double wi : w)
      factor2 += wi * wi;
    scaled.push_back(std::abs(value[k] - predicted) / std::sqrt(factor2));
  }
  // For a normal distribution the median of |x| is 0.6745 σ.
  return median(scaled) / 0.6744897501960817;
}

ScanNoise estimate_scan_noise(const FluxScan &scan)
{
  ScanNoise n;
  n.Bn = estimate_noise(scan.angle, scan.Bn);
  if (scan.has_tangential())
    n.Bt = estimate_noise(scan.angle, scan.Bt);
  n.samples = scan.size() >= 5 ? scan.size() - 4 : 0;
  return n;
}

} // namespace magbrush
