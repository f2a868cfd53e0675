// The exact magnetostatic force between two magnetisable spheres in a uniform applied field,
// by the classical multipole re-expansion series (Jeffrey 1973; Clercx & Bossis 1993;
// Keaveny & Maxey 2008 for the magnetic case).
//
// Sphere 1 (radius a1, relative permeability μ1) sits at the origin, sphere 2 (a2, μ2) at
// d ẑ. The applied field H0 is uniform. Outside the spheres the magnetic scalar potential
// (H = −∇φ) is the applied one plus the exterior multipoles of each sphere,
//   φ = φ0 + Σ_l A_l r1^−(l+1) P_l^m(cos θ1) cos mϕ + Σ_l B_l r2^−(l+1) P_l^m(cos θ2) cos mϕ,
// with m = 0 for H0 along the line of centres and m = 1 for H0 across it (along x); inside
// each sphere φ is regular. Re-expanding sphere 2's multipoles about centre 1,
//   r2^−(n+1) P_n^m(cos θ2) = Σ_l (−1)^(n+m) (l+n)! / ((l+m)!(n−m)!) r1^l P_l^m(cos θ1) / d^(l+n+1),
// (and the mirror image about centre 2, with (−1)^(l+m)), the interface conditions
// (φ continuous, μ ∂φ_in/∂r = ∂φ_out/∂r) give, order by order,
//   A_l = −γ_l E_l,   γ_l = l(μ − 1)/(lμ + l + 1) a^(2l+1),
// where E_l is the regular (incident) part at sphere 1: the applied field plus sphere 2's
// re-expanded multipoles. Truncating at L orders gives a 2L × 2L dense linear system.
//
// Forces (per μ0 H0², so in m²), two independent ways:
//  * energy: for linear bodies in a fixed uniform applied field the co-energy is
//    U = −(μ0/2) H0·m_total, m_total = 4π(A_1 + B_1) (the dipole moments of both spheres).
//    The force on sphere 2 along the axis is −∂U/∂d (the derivative of the solution is
//    exact: dx/dd = −M⁻¹ (dM/dd) x). A pair with the field at angle ψ to the axis has
//    U(d, ψ) = −2π μ0 H0² [cos²ψ S∥(d) + sin²ψ S⊥(d)], S = A_1 + B_1 per unit field, so
//      F·r̂ = μ0 H0² [f∥ cos²ψ + f⊥ sin²ψ],   f = 2π dS/dd,
//      F·t̂ = μ0 H0² f_t sinψ cosψ,           f_t = −4π (S∥ − S⊥)/d,
//    with t̂ the direction in which sphere 2 moves when ψ grows (−∂U/(d ∂ψ)).
//  * Maxwell stress: ∮ μ0 (H H − ½ H² I)·n dS over a sphere around sphere 2 (in air),
//    with H from the same coefficients expanded about centre 2.
#pragma once

#include <vector>

namespace magbrush::magnetics {

struct TwoSphereGeometry
{
  double a1 = 1.0, a2 = 1.0;     // radii [m]
  double mu1 = 1.0, mu2 = 1.0;   // relative permeabilities
  double d = 2.0;                // centre distance [m], ≥ a1 + a2
};

// The truncated series solution for one field orientation (m = 0: along, m = 1: across),
// for a unit applied field H0 = 1 A/m.
class TwoSphereSeries
{
public:
  TwoSphereSeries(const TwoSphereGeometry &geometry, int m, int orders);

  int orders() const { return L_; }
  // Dipole sum S = A_1 + B_1 [m³] (total moment = 4π S H0) and its derivative dS/dd [m²].
  double dipole_sum() const { return (A_[1] + B_[1]) * s_ * s_ * s_; }
  double dipole_sum_derivative() const { return (dA1_ + dB1_) * s_ * s_; }
  // Moments of the two spheres per unit applied field [A m² per A/m = m³]: 4π A_1, 4π B_1.
  double moment1() const { return 4.0 * 3.14159265358979323846 * A_[1] * s_ * s_ * s_; }
  double moment2() const { return 4.0 * 3.14159265358979323846 * B_[1] * s_ * s_ * s_; }

  // H (per unit H0) at a point given relative to centre 2 in spherical coordinates
  // (valid for a2 ≤ r < d − a1): components in the Cartesian frame.
  void field_near_sphere2(double r, double theta, double phi, double H[3]) const;

private:
  // Lengths are scaled by s_ = a1 inside (the coefficients grow like a^(2l+1)): g_ holds the
  // scaled geometry and A_, B_, E2_ the scaled coefficients.
  double s_ = 1.0;
  TwoSphereGeometry g_;
  int m_, L_;
  std::vector<double> A_, B_; // indices 1..L
  std::vector<double> E2_;    // regular coefficients about centre 2 (incl. the applied field)
  double dA1_ = 0.0, dB1_ = 0.0;
};

// Force on sphere 2 per μ0 H0² [m²] in the quadratic-form decomposition above.
struct TwoSphereForce
{
  double parallel = 0.0;      // f∥: radial force, field along the axis (< 0: attraction)
  double perpendicular = 0.0; // f⊥: radial force, field across the axis (> 0: repulsion)
  double transverse = 0.0;    // f_t: coefficient of sinψ cosψ along t̂
  int orders = 0;             // series orders used
};

// Energy-derivative force at a fixed truncation.
TwoSphereForce two_sphere_force_energy(const TwoSphereGeometry &g, int orders);

// Maxwell-stress force at a fixed truncation, on a sphere of radius R around centre 2
// (a2 ≤ R < d − a1; R ≤ 0 means R = a2).
TwoSphereForce two_sphere_force_stress(const TwoSphereGeometry &g, int orders, double R = 0.0);

// Energy-derivative force with the truncation raised (×1.5) until every component changes by
// less than rel_tol (relative to |f∥|) between successive truncations; throws if
// max_orders is reached first.
TwoSphereForce two_sphere_force(const TwoSphereGeometry &g, double rel_tol = 1e-9,
                                int max_orders = 800);

// Closed forms of the point-dipole models for two identical spheres (radius a, factor β) in
// a uniform field, per μ0 H0² [m²], same decomposition (D = d/a):
//  * point dipoles (moments from the applied field only):
//      f∥ = −24π β² a²/D⁴,  f⊥ = 12π β² a²/D⁴,  f_t = −24π β² a²/D⁴
//  * mutual dipoles (isolated pair, self-consistent): moments scaled by 1/(1 − 2β/D³) along
//    and 1/(1 + β/D³) across the axis, so f∥ gets 1/(1 − 2β/D³)², f⊥ 1/(1 + β/D³)² and
//    f_t 1/((1 − 2β/D³)(1 + β/D³)).
TwoSphereForce point_dipole_pair_force(double a, double beta, double d);
TwoSphereForce mutual_dipole_pair_force(double a, double beta, double d);

} // namespace magbrush::magnetics
