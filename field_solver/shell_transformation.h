// The shell transformation: an open (unbounded) 2D exterior on a bounded mesh.
//
// The roller's field decays like a 2D multipole, A ~ r^-n, and only reaches zero at infinity.
// Truncating the domain at a circle with A = 0 costs 17 % at 2 R (1.7 % at 5 R). Instead, the
// outer annulus R1 < ρ < R2 of the mesh stands for the whole exterior R1 < r < ∞ through the
// radial stretch (angle unchanged)
//
//     r(ρ) = R1 (R2 − R1) / (R2 − ρ),        r(R1) = R1,   r(ρ → R2) → ∞,
//
// and A = 0 on ρ = R2 is then the exact condition A(∞) = 0.
//
// Derivation of the transformed coefficient. In physical polar coordinates the energy is
//
//     ∫ ν ∇A·∇v dx = ∫∫ ν ( A_r v_r + A_θ v_θ / r² ) r dr dθ.
//
// Substitute r = r(ρ): A_r = A_ρ / r', dr = r' dρ, so
//
//     = ∫∫ ν ( A_ρ v_ρ r / (r' ρ)  +  A_θ v_θ (r' ρ / r) / ρ² ) ρ dρ dθ,
//
// which is the energy of an anisotropic medium on the mesh (coordinates ρ, θ) with the tensor
//
//     K = ν ( a ρ̂ ρ̂ᵀ + b θ̂ θ̂ᵀ ),   a = r / (ρ r'),   b = ρ r' / r = 1 / a.
//
// For the map above r / r' = R2 − ρ, hence
//
//     a = (R2 − ρ) / ρ,   b = ρ / (R2 − ρ),   det K = ν².
//
// b blows up at R2, but a multipole A ~ r^-n = ((R2 − ρ)/(R1 (R2 − R1)))^n makes
// b A_θ² ~ (R2 − ρ)^(2n−1) integrable; the dipole (n = 1) is even linear in ρ and is
// represented exactly by the elements. Any source term vanishes in the shell (it is air), so
// only the coefficient changes. The same tensor serves electrostatics with ν → ε.
//
// Header-only and free of deal.II so that it can be tested on its own.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::field {

class ShellTransformation
{
public:
  ShellTransformation() = default;
  ShellTransformation(double inner_radius, double outer_radius, double cx = 0.0, double cy = 0.0)
    : R1(inner_radius), R2(outer_radius), center{{cx, cy}}
  {
    if (!(R1 > 0.0 && R2 > R1))
      throw std::invalid_argument("shell transformation: expected 0 < R1 < R2, found R1 = " +
                                  std::to_string(R1) + " m, R2 = " + std::to_string(R2) +
                                  " m; increase field.outer_radius_factor");
  }

  double inner_radius() const { return R1; }
  double outer_radius() const { return R2; }

  // Physical radius r(ρ) that the mesh radius ρ stands for.
  double physical_radius(double rho) const { return R1 * (R2 - R1) / (R2 - rho); }

  // Mesh radius ρ(r) of a physical radius r ≥ R1 (inverse of physical_radius).
  double mesh_radius(double r) const { return R2 - R1 * (R2 - R1) / r; }

  // The Cartesian tensor K / ν at mesh point (x, y) inside the shell, as
  // {K_xx, K_xy, K_yy}. Uses a = (R2 − ρ)/ρ along ρ̂ and b = 1/a along θ̂.
  std::array<double, 3> relative_tensor(double x, double y) const
  {
    const double dx = x - center[0], dy = y - center[1];
    const double rho = std::hypot(dx, dy);
    const double a = (R2 - rho) / rho;
    const double b = 1.0 / a;
    const double c = dx / rho, s = dy / rho;
    return {{a * c * c + b * s * s, (a - b) * c * s, a * s * s + b * c * c}};
  }

private:
  double R1 = 1.0, R2 = 2.0;
  std::array<double, 2> center{{0.0, 0.0}};
};

} // namespace magbrush::field
