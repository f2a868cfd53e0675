// Independent references for the periodic Coulomb sums, in kernel units (a unit charge, no
// 1/(4πε0)): the field of a periodic ROW of charges by the Bessel-K (Lekner-type) series, and
// the field and potential of a periodic SHEET (two periodic axes) by 2D Ewald summation.
#pragma once

#include <cmath>

namespace magbrush::electrostatics::testing {

constexpr double pi = 3.14159265358979323846;

// Field E = −∇φ at (x, y, z) of unit charges at (0, 0, jL), j ∈ ℤ (row along z):
//   E_ρ = 2/(Lρ) + (8π/L²) Σ_m m K1(2πmρ/L) cos(2πmz/L),
//   E_z = (8π/L²) Σ_m m K0(2πmρ/L) sin(2πmz/L),
// summed until the Bessel functions fall below 1e-18 of the leading term.
inline void row_field(double x, double y, double z, double L, double E[3])
{
  const double rho = std::sqrt(x * x + y * y);
  double er = 2.0 / (L * rho), ez = 0.0;
  for (int m = 1;; ++m)
  {
    const double a = 2.0 * pi * m * rho / L;
    if (a > 45.0)
      break;
    const double c = 8.0 * pi / (L * L) * m;
    er += c * std::cyl_bessel_k(1.0, a) * std::cos(2.0 * pi * m * z / L);
    ez += c * std::cyl_bessel_k(0.0, a) * std::sin(2.0 * pi * m * z / L);
  }
  E[0] = er * x / rho;
  E[1] = er * y / rho;
  E[2] = ez;
}

// Potential and field at (x, y, z) of unit charges at (i Lx, 0, k Lz) (a sheet periodic along
// x and z, open along y), by 2D Ewald summation with splitting α:
//   φ = Σ_n erfc(α|r_n|)/|r_n|
//     + (π/A) Σ_{G≠0} cos(G·ρ)/G [e^(Gy) erfc(G/2α + αy) + e^(−Gy) erfc(G/2α − αy)]
//     − (2π/A) [y erf(αy) + e^(−α²y²)/(α√π)],
// which tends to −2π|y|/A far from the sheet (no constant: the convention of the cell
// multipole's regularised sums). E = −∇φ analytically. `skip_origin` leaves out the n = 0
// real-space term's bare 1/r part (the field of a charge's own periodic images at itself).
inline void sheet_field(double x, double y, double z, double Lx, double Lz, double E[3], double &phi,
                        bool skip_origin = false)
{
  const double A = Lx * Lz, alpha = 2.5 / std::sqrt(A), sp = std::sqrt(pi);
  phi = 0.0;
  E[0] = E[1] = E[2] = 0.0;
  const int nr = 8, ng = 10;
  for (int i = -nr; i <= nr; ++i)
    for (int k = -nr; k <= nr; ++k)
    {
      const double rx = x - i * Lx, ry = y, rz = z - k * Lz;
      const double r = std::sqrt(rx * rx + ry * ry + rz * rz);
      double f = std::erfc(alpha * r) / r;
      double g = (std::erfc(alpha * r) / r + 2.0 * alpha / sp * std::exp(-alpha * alpha * r * r)) / (r * r);
      if (skip_origin && i == 0 && k == 0)
      {
        // erfc(αr)/r − 1/r = −erf(αr)/r; its gradient at r → 0 vanishes by symmetry.
        if (r == 0.0)
        {
          phi += -2.0 * alpha / sp;
          continue;
        }
        f -= 1.0 / r;
        g -= 1.0 / (r * r * r);
      }
      phi += f;
      E[0] += g * rx;
      E[1] += g * ry;
      E[2] += g * rz;
    }
  for (int i = -ng; i <= ng; ++i)
    for (int k = -ng; k <= ng; ++k)
    {
      if (i == 0 && k == 0)
        continue;
      const double gx = 2.0 * pi * i / Lx, gz = 2.0 * pi * k / Lz, G = std::sqrt(gx * gx + gz * gz);
      const double a = G / (2.0 * alpha);
      const double up = std::exp(G * y) * std::erfc(a + alpha * y);
      const double down = std::exp(-G * y) * std::erfc(a - alpha * y);
      const double dup = G * up - 2.0 * alpha / sp * std::exp(G * y - (a + alpha * y) * (a + alpha * y));
      const double ddown = -G * down + 2.0 * alpha / sp * std::exp(-G * y - (a - alpha * y) * (a - alpha * y));
      const double c = std::cos(gx * x + gz * z), s = std::sin(gx * x + gz * z);
      phi += pi / A * c / G * (up + down);
      E[0] += pi / A * gx * s / G * (up + down);
      E[2] += pi / A * gz * s / G * (up + down);
      E[1] -= pi / A * c / G * (dup + ddown);
    }
  phi -= 2.0 * pi / A * (y * std::erf(alpha * y) + std::exp(-alpha * alpha * y * y) / (alpha * sp));
  E[1] += 2.0 * pi / A * std::erf(alpha * y);
}

} // namespace magbrush::electrostatics::testing
