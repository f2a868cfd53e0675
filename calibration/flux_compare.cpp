// Profile comparison: errors, per-pole peaks, residual file (see flux_compare.h).
#include "calibration/flux_compare.h"

#include "common/atomic_file.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>


namespace magbrush {

namespace {

constexpr double pi = M_PI;
constexpr double to_deg = 180.0 / M_PI;

double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2.0 * pi);
  return a <= -pi ? a + 2.0 * pi : a;
}

double wrap_0_2pi(double a)
{
  a = std::fmod(a, 2.0 * pi);
  return a < 0 ? a + 2.0 * pi : a;
}

ComponentErrors errors_of(const std::vector<double> &angle, const std::vector<double> &measured,
                          const std::vector<double> &computed)
{
  ComponentErrors e;
  double sum = 0.0;
  for (size_t k = 0; k < measured.size(); ++k)
  {
    const double d = measured[k] - computed[k];
    sum += d * d;
    if (std::abs(d) > e.max)
    {
      e.max = std::abs(d);
      e.max_angle = angle[k];
    }
    e.peak = std::max(e.peak, std::abs(measured[k]));
  }
  e.rms = std::sqrt(sum / std::max<size_t>(measured.size(), 1));
  return e;
}

// Extrema of B that stand out (|B| ≥ 20 % of the largest, the largest |B| of their sign within
// ±10°) and lie more than 10° from every matched pole peak.
std::vector<PeakMatch> unmatched_extrema(const std::vector<double> &angle, const std::vector<double> &B,
                                         const std::vector<PeakMatch> &matched)
{
  const double radius = 10.0 * pi / 180.0;
  double largest = 0.0;
  for (double b : B)
    largest = std::max(largest, std::abs(b));
  std::vector<PeakMatch> out;
  for (size_t k = 0; k < B.size(); ++k)
  {
    if (std::abs(B[k]) < 0.2 * largest)
      continue;
    bool extremum = true;
    for (size_t j = 0; j < B.size() && extremum; ++j)
      if (j != k && std::abs(wrap_pm_pi(angle[j] - angle[k])) <= radius &&
          B[j] * B[k] > 0.0 && std::abs(B[j]) > std::abs(B[k]))
        extremum = false;
    if (!extremum)
      continue;
    bool explained = false;
    for (const auto &m : matched)
      explained = explained || (m.found && std::abs(wrap_pm_pi(m.angle - angle[k])) <= radius &&
                                m.value * B[k] > 0.0);
    if (!explained)
      out.push_back({true, wrap_0_2pi(angle[k]), B[k]});
  }
  return out;
}

} // namespace

std::vector<PeakMatch> find_pole_peaks(const std::vector<Pole> &poles,
                                       const std::vector<double> &angle,
                                       const std::vector<double> &B, double offset)
{
  const size_t m = angle.size();
  std::vector<PeakMatch> peaks(poles.size());
  if (m < 3)
    return peaks;
  // Does the scan close on itself (a full turn)? Then index neighbours wrap around.
  const double step = std::abs(angle[1] - angle[0]);
  const bool full_turn = std::abs(angle.back() - angle.front()) + 1.5 * step >= 2.0 * pi;
  for (size_t i = 0; i < poles.size(); ++i)
  {
    const double target = poles[i].angle - offset;
    double half_window = pi;
    for (size_t j = 0; j < poles.size(); ++j)
      if (j != i)
        half_window = std::min(half_window, 0.5 * std::abs(wrap_pm_pi(poles[j].angle - poles[i].angle)));
    half_window = std::max(half_window, 5.0 * pi / 180.0);
    const double sign = poles[i].strength >= 0 ? 1.0 : -1.0;
    long best = -1;
    for (size_t k = 0; k < m; ++k)
      if (std::abs(wrap_pm_pi(angle[k] - target)) <= half_window &&
          (best < 0 || sign * B[k] > sign * B[best]))
        best = static_cast<long>(k);
    if (best < 0 || sign * B[best] <= 0.0)
      continue;
    // A resolved peak has samples on both sides that are lower (not the end of a partial scan).
    long prev = best - 1, next = best + 1;
    if (full_turn)
    {
      prev = (prev + long(m)) % long(m);
      next = next % long(m);
    }
    if (prev < 0 || next >= long(m) || sign * B[prev] > sign * B[best] ||
        sign * B[next] > sign * B[best])
      continue;
    // Refine by a least-squares parabola through the top of the peak: the contiguous samples
    // within 5 % of the largest one (at least its two neighbours). On a noisy scan a
    // three-point parabola would follow the noise; the top of a smooth pole peak is very
    // nearly quadratic, and a flat peak gets a wider window than a sharp one.
    const double level = 0.95 * sign * B[best];
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    double lo = 0.0, hi = 0.0;
    for (size_t k = 0; k < m; ++k)
    {
      const double x = wrap_pm_pi(angle[k] - angle[best]);
      if ((sign * B[k] < level || std::abs(x) > half_window) && long(k) != prev && long(k) != next)
        continue;
      if (!full_turn && ((x < 0) != (long(k) < best)) && x != 0.0)
        continue; // a partial scan does not wrap
      const Eigen::Vector3d phi(1.0, x, x * x);
      normal += phi * phi.transpose();
      rhs += phi * B[k];
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    const Eigen::Vector3d q = normal.ldlt().solve(rhs);
    double x = 0.0, value = B[best];
    if (q(2) * sign < 0.0) // a maximum of sign·B
    {
      x = std::clamp(-q(1) / (2.0 * q(2)), lo, hi);
      value = q(0) + q(1) * x + q(2) * x * x;
    }
    if (std::abs(wrap_pm_pi(angle[best] + x - target)) > half_window)
      continue;
    peaks[i].found = true;
    peaks[i].angle = wrap_0_2pi(angle[best] + x);
    peaks[i].value = value;
  }
  return peaks;
}

FluxComparison compare_flux(const FluxScan &scan, const std::vector<double> &computed_Bn,
                            const std::vector<double> &computed_Bt, const std::vector<Pole> &poles)
{
  if (computed_Bn.size() != scan.size() ||
      (scan.has_tangential() && computed_Bt.size() != scan.size()))
    throw std::invalid_argument("compare_flux: the computed profile must be sampled at the "
                                "scan's angles");
  FluxComparison c;
  c.angle = scan.angle;
  c.measured_Bn = scan.Bn;
  c.measured_Bt = scan.Bt;
  c.computed_Bn = computed_Bn;
  c.computed_Bt = computed_Bt;
  c.has_tangential = scan.has_tangential();
  c.Bn = errors_of(scan.angle, scan.Bn, computed_Bn);
  if (c.has_tangential)
    c.Bt = errors_of(scan.angle, scan.Bt, computed_Bt);
  const auto computed = find_pole_peaks(poles, scan.angle, computed_Bn);
  const auto measured = find_pole_peaks(poles, scan.angle, scan.Bn);
  for (size_t i = 0; i < poles.size(); ++i)
    c.peaks.push_back({poles[i].name, computed[i], measured[i]});
  c.unmatched = unmatched_extrema(scan.angle, scan.Bn, measured);
  if (c.has_tangential)
  {
    double mm = 0, cc = 0, mc = 0;
    for (size_t k = 0; k < scan.size(); ++k)
    {
      mm += scan.Bt[k] * scan.Bt[k];
      cc += computed_Bt[k] * computed_Bt[k];
      mc += scan.Bt[k] * computed_Bt[k];
    }
    c.tangential_correlation = mm > 0 && cc > 0 ? mc / std::sqrt(mm * cc) : 0.0;
  }
  return c;
}

std::string format_errors(const FluxComparison &c)
{
  char buf[512];
  std::ostringstream out;
  out << "  component   RMS error    max error   (at angle)   max |measured|   RMS/max\n";
  auto row = [&](const char *name, const ComponentErrors &e) {
    std::snprintf(buf, sizeof buf, "  %-9s  %7.3f mT   %7.3f mT   (%6.1f deg)   %8.2f mT     %5.2f %%\n",
                  name, e.rms * 1e3, e.max * 1e3, wrap_0_2pi(e.max_angle) * to_deg, e.peak * 1e3,
                  e.peak > 0 ? 100.0 * e.rms / e.peak : 0.0);
    out << buf;
  };
  row("Bn", c.Bn);
  if (c.has_tangential)
    row("Bt", c.Bt);
  if (c.has_tangential && c.tangential_correlation < -0.5)
    out << "  note: the measured Bt is anti-correlated with the computed one (correlation "
        << c.tangential_correlation
        << "): the probe's tangential sign is probably clockwise-positive; pass --flip-bt\n";
  return out.str();
}

std::string format_peaks(const FluxComparison &c)
{
  char buf[512];
  std::ostringstream out;
  out << "  pole   computed: angle   Bn peak    measured: angle   Bn peak     Δangle    Δ|Bn|\n";
  for (const auto &p : c.peaks)
  {
    auto cell = [](const PeakMatch &m, char *s, size_t n) {
      if (m.found)
        std::snprintf(s, n, "%7.2f deg %8.2f mT", m.angle * to_deg, m.value * 1e3);
      else
        std::snprintf(s, n, "%-22s", "    (no peak)");
    };
    char a[64], b[64], d[96] = "";
    cell(p.computed, a, sizeof a);
    cell(p.measured, b, sizeof b);
    if (p.computed.found && p.measured.found)
      std::snprintf(d, sizeof d, "%+7.2f deg %+6.2f %%",
                    wrap_pm_pi(p.measured.angle - p.computed.angle) * to_deg,
                    100.0 * (std::abs(p.measured.value) - std::abs(p.computed.value)) /
                        std::abs(p.computed.value));
    std::snprintf(buf, sizeof buf, "  %-5s  %s    %s   %s\n", p.pole.c_str(), a, b, d);
    out << buf;
  }
  for (const auto &u : c.unmatched)
  {
    std::snprintf(buf, sizeof buf,
                  "  note: the scan has a %s peak of %.2f mT at %.1f deg that no pole of the case "
                  "accounts for (a pole missing from the case, or one with the wrong sign?)\n",
                  u.value > 0 ? "north (Bn > 0)" : "south (Bn < 0)", u.value * 1e3, u.angle * to_deg);
    out << buf;
  }
  return out.str();
}

void write_residuals_csv(const std::string &path, const FluxComparison &c)
{
  std::ostringstream out;
  char buf[256];
  out << "# magbrush flux: measured and computed sleeve flux density, residual = measured - computed\n";
  out << (c.has_tangential
              ? "angle_deg,Bn_measured_mT,Bn_computed_mT,Bn_residual_mT,Bt_measured_mT,Bt_computed_mT,Bt_residual_mT\n"
              : "angle_deg,Bn_measured_mT,Bn_computed_mT,Bn_residual_mT\n");
  for (size_t k = 0; k < c.angle.size(); ++k)
  {
    std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g,%.6g", c.angle[k] * to_deg, c.measured_Bn[k] * 1e3,
                  c.computed_Bn[k] * 1e3, (c.measured_Bn[k] - c.computed_Bn[k]) * 1e3);
    out << buf;
    if (c.has_tangential)
    {
      std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g", c.measured_Bt[k] * 1e3,
                    c.computed_Bt[k] * 1e3, (c.measured_Bt[k] - c.computed_Bt[k]) * 1e3);
      out << buf;
    }
    out << "\n";
  }
  write_text_atomically(path, out.str());
}

} // namespace magbrush
