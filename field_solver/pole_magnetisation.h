// The Gaussian pole model of the magnet (Kweon eq. 9–10, our reading):
//
//     M(r, θ) = r̂ Σ_i M_i exp(−α_i wrap(θ − φ_i)²),   wrap() into (−π, π],
//
// radial, with the pole's sign carried by M_i (north: outward). In the A_z weak form the
// magnet enters as the source s = (−M_y, M_x)/μr (potential_problem.h).
//
// Also its Fourier series M_r(θ) = c_0 + Σ_n [a_n cos nθ + b_n sin nθ], which turns the whole
// roller into a sum of multipole rings with exact solutions (used by the verification tests).
// Header-only, no deal.II.
#pragma once

#include "case/case_model.h"

#include <cmath>
#include <vector>

namespace magbrush::field {

inline double wrap_angle(double angle)
{
  constexpr double pi = 3.14159265358979323846;
  double a = std::fmod(angle + pi, 2.0 * pi);
  if (a <= 0.0)
    a += 2.0 * pi;
  return a - pi; // (−π, π]
}

// M_r(θ) [A/m] of the pole set.
inline double radial_magnetisation(const std::vector<Pole> &poles, double theta)
{
  double m = 0.0;
  for (const auto &p : poles)
  {
    const double d = wrap_angle(theta - p.angle);
    m += p.strength * std::exp(-p.shape_factor * d * d);
  }
  return m;
}

// Fourier coefficients of M_r(θ) up to n_max, from n_samples equally spaced samples
// (trapezoidal rule = exact for trigonometric polynomials of degree < n_samples/2; the
// Gaussians are smooth and periodic, so this converges spectrally).
struct FourierSeries
{
  double c0 = 0.0;
  std::vector<double> a, b; // a[n], b[n] for n = 0..n_max (index 0 unused)
};

inline FourierSeries fourier_series(const std::vector<Pole> &poles, int n_max,
                                    int n_samples = 4096)
{
  constexpr double pi = 3.14159265358979323846;
  FourierSeries f;
  f.a.assign(n_max + 1, 0.0);
  f.b.assign(n_max + 1, 0.0);
  for (int k = 0; k < n_samples; ++k)
  {
    const double theta = 2.0 * pi * k / n_samples;
    const double m = radial_magnetisation(poles, theta);
    f.c0 += m / n_samples;
    for (int n = 1; n <= n_max; ++n)
    {
      f.a[n] += 2.0 * m * std::cos(n * theta) / n_samples;
      f.b[n] += 2.0 * m * std::sin(n * theta) / n_samples;
    }
  }
  return f;
}

} // namespace magbrush::field
