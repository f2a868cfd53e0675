// The point-dipole physics of magnetisable carrier beads (Kawamoto A8–A11, Kweon eq. 2–5),
// as small inline kernels shared by the many-body solver, the tests and the benchmarks.
//
// Conventions: B in tesla, dipole moments p in A·m² (so that a bead in a field B carries
// p = (4π/μ0) β a³ B), positions in metres, forces in newtons.
#pragma once

#include <cmath>

namespace magbrush::magnetics {

constexpr double pi = 3.14159265358979323846;
constexpr double mu0 = 4.0e-7 * pi; // vacuum permeability [T m/A]

// Clausius–Mossotti factor of a linear sphere: β = (μr − 1)/(μr + 2).
inline double clausius_mossotti(double mu_r) { return (mu_r - 1.0) / (mu_r + 2.0); }

// The inverse: μr = (1 + 2β)/(1 − β).
inline double mu_r_from_beta(double beta) { return (1.0 + 2.0 * beta) / (1.0 - beta); }

// Linear polarisability α with p = α B_local: α = (4π/μ0) β a³ (Kawamoto A10).
inline double polarisability(double radius, double beta)
{
  return 4.0 * pi / mu0 * beta * radius * radius * radius;
}

// The dipole field tensor, stored as its 6 independent components (xx, yy, zz, xy, xz, yz):
// the field at r (relative to a dipole p) is B = T(r) p with
//   T(r) = (μ0/4π) (3 r̂ r̂ − I) / |r|³          (Kawamoto A11).
// T is symmetric and even in r, so the same tensor serves both members of a pair.
struct DipoleTensor
{
  double xx, yy, zz, xy, xz, yz;

  static DipoleTensor at(const double r[3])
  {
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    const double inv_r = 1.0 / std::sqrt(r2);
    const double inv_r3 = inv_r * inv_r * inv_r;
    const double c = mu0 / (4.0 * pi) * inv_r3;
    const double ex = r[0] * inv_r, ey = r[1] * inv_r, ez = r[2] * inv_r;
    return {c * (3 * ex * ex - 1), c * (3 * ey * ey - 1), c * (3 * ez * ez - 1),
            c * 3 * ex * ey,       c * 3 * ex * ez,       c * 3 * ey * ez};
  }

  void add_field(const double p[3], double B[3]) const
  {
    B[0] += xx * p[0] + xy * p[1] + xz * p[2];
    B[1] += xy * p[0] + yy * p[1] + yz * p[2];
    B[2] += xz * p[0] + yz * p[1] + zz * p[2];
  }
};

// Force on dipole p_j at r_j from dipole p_k at r_k, r = r_j − r_k (Kawamoto's
// (p_j·∇)B_kj written out):
//   F = (3μ0 / 4π|r|⁴) [ (p_j·r̂) p_k + (p_k·r̂) p_j + (p_j·p_k) r̂ − 5 (p_j·r̂)(p_k·r̂) r̂ ].
// It is odd in r and symmetric in (j, k): the force on k is exactly −F (Newton's third law).
inline void dipole_pair_force(const double r[3], const double pj[3], const double pk[3],
                              double F[3])
{
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  const double inv_r = 1.0 / std::sqrt(r2);
  const double e[3] = {r[0] * inv_r, r[1] * inv_r, r[2] * inv_r};
  const double c = 3.0 * mu0 / (4.0 * pi) * inv_r * inv_r * inv_r * inv_r;
  const double pje = pj[0] * e[0] + pj[1] * e[1] + pj[2] * e[2];
  const double pke = pk[0] * e[0] + pk[1] * e[1] + pk[2] * e[2];
  const double pjk = pj[0] * pk[0] + pj[1] * pk[1] + pj[2] * pk[2];
  const double radial = pjk - 5.0 * pje * pke;
  for (int d = 0; d < 3; ++d)
    F[d] = c * (pje * pk[d] + pke * pj[d] + radial * e[d]);
}

// Induced moment of a sphere (radius a, Clausius–Mossotti factor β) in the local field B
// (the field at its centre from everything but itself).
//
// Linear (M_s = 0): p = (4π/μ0) β a³ B.
// Saturating (M_s > 0): Fröhlich–Kennelly law for the bead material,
//   M(H_in) = χ0 M_s H_in / (M_s + χ0 H_in),   χ0 = μr − 1,
// with the uniform-magnetisation demagnetising field of a sphere, H_in = H_loc − M/3. The
// scalar equation H_in + M(H_in)/3 = H_loc is a quadratic in H_in,
//   3χ0 H_in² + [M_s(3 + χ0) − 3χ0 H_loc] H_in − 3 H_loc M_s = 0,
// whose positive root we take in the cancellation-free form. Then p = (4π/3) a³ M B̂.
// Limits: H_loc → 0 gives back the linear law (M = 3β H_loc); H_loc → ∞ gives M → M_s.
inline void induced_moment(double radius, double beta, double saturation_magnetisation,
                           const double B[3], double p[3])
{
  if (saturation_magnetisation <= 0.0)
  {
    const double alpha = polarisability(radius, beta);
    for (int d = 0; d < 3; ++d)
      p[d] = alpha * B[d];
    return;
  }
  const double Bmag = std::sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]);
  if (Bmag == 0.0 || beta <= 0.0)
  {
    p[0] = p[1] = p[2] = 0.0;
    return;
  }
  const double Ms = saturation_magnetisation;
  const double chi0 = mu_r_from_beta(beta) - 1.0;
  const double h = Bmag / mu0;
  const double b = Ms * (3.0 + chi0) - 3.0 * chi0 * h;
  const double disc = std::sqrt(b * b + 36.0 * chi0 * h * Ms);
  const double h_in = b > 0.0 ? 6.0 * h * Ms / (b + disc) : (-b + disc) / (6.0 * chi0);
  const double M = chi0 * Ms * h_in / (Ms + chi0 * h_in);
  const double scale = 4.0 * pi / 3.0 * radius * radius * radius * M / Bmag;
  for (int d = 0; d < 3; ++d)
    p[d] = scale * B[d];
}

} // namespace magbrush::magnetics
