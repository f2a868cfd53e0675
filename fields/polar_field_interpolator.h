// The roller's magnetic field at a particle: B and ∇B from the vector potential A_z stored on
// a polar grid (field_grid.h). This is what the DEM calls per carrier per magnetic refresh.
//
// B = curl(A_z ẑ):  B_x = ∂A/∂y,  B_y = −∂A/∂x,  B_z = 0  (a 2D field, z ignored).
// A_z is interpolated by a tensor-product cubic spline (not-a-knot in r, periodic in θ), so
//  * B is C1 and ∇B is continuous everywhere in the annulus, the seam θ = 0/2π included;
//  * ∇·B = ∂²A/∂x∂y − ∂²A/∂y∂x = 0 exactly (to round-off), whatever the grid;
//  * curl B = −∇²A vanishes in air only to interpolation accuracy (O(h²));
//  * errors: A O(h⁴), B O(h³), ∇B O(h²) (measured in tests/fields).
//
// Where the point lies:
//  * r_min ≤ r ≤ r_max: the spline.
//  * r > r_max: the exterior multipole continuation of the outermost ring,
//      A(r, θ) = a_0 + Σ_{n=1..K} (r_max/r)^n (a_n cos nθ + b_n sin nθ),
//    with a_n, b_n the Fourier coefficients of A on r = r_max. It is the exact field when
//    there are no sources beyond r_max (the roller alone: true; a magnetic blade outside the
//    grid: not true — make the grid cover it). Continuous with the spline to interpolation
//    accuracy, decays like the field of the roller, never a jump to zero.
//  * r < r_min − Δr/2 (inside the sleeve, where no particle can be): evaluate() throws
//    FieldLookupError; try_evaluate() returns false. Between r_min − Δr/2 and r_min the
//    boundary cell's polynomial is extended (a particle pressed into the sleeve by its
//    contact overlap still gets a sensible field).
//
// Cost: one atan2, one sqrt and a 4×4 Hermite patch; no allocation, no virtual call.
#pragma once

#include "case/case_model.h"
#include "fields/field_grid.h"

#include <array>
#include <complex>
#include <stdexcept>
#include <vector>

namespace magbrush {

// A field lookup at a point where the field is not defined (inside the sleeve).
struct FieldLookupError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

class PolarFieldInterpolator
{
public:
  // tail_harmonics: number K of multipole terms kept beyond r_max; −1 = automatic (the
  // smallest K whose omitted Fourier amplitude is below 1e-8 of the total, at most 128).
  explicit PolarFieldInterpolator(const PolarGrid &grid, int tail_harmonics = -1);

  // B [T] and gradB[i][j] = ∂B_i/∂x_j [T/m] at x [m]. Throws FieldLookupError inside the sleeve.
  void evaluate(const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &gradB) const;
  // B only (a convenience: it costs the same as evaluate()).
  Vec3 field(const Vec3 &x) const;
  // As evaluate(), but returns false (B = 0, ∇B = 0) inside the sleeve instead of throwing.
  bool try_evaluate(const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &gradB) const noexcept;
  // The interpolated vector potential A_z [T·m] (for tests and plots).
  double vector_potential(const Vec3 &x) const;

  double r_min() const { return r_min_; }
  double r_max() const { return r_max_; }
  double dr() const { return dr_; }
  double dtheta() const { return dtheta_; }
  int tail_harmonics() const { return static_cast<int>(tail_.size()); }
  // Bytes held for lookups (node data and tail coefficients).
  size_t memory_bytes() const;

private:
  // A and its Cartesian first and second derivatives at a point.
  struct Potential
  {
    double A, A_x, A_y, A_xx, A_xy, A_yy;
  };
  enum class Where { inside_sleeve, grid, tail };

  Where locate(double r) const
  {
    if (r > r_max_)
      return Where::tail;
    return r >= r_min_ - 0.5 * dr_ ? Where::grid : Where::inside_sleeve;
  }
  Potential from_grid(double x, double y, double r) const;
  Potential from_tail(double x, double y) const;
  [[noreturn]] void throw_inside_sleeve(const Vec3 &x, double r) const;

  double r_min_, r_max_, dr_, dtheta_, inv_dr_ = 0, inv_dtheta_ = 0;
  int n_r_, n_theta_;
  std::vector<double> nodes_;                 // [f, f_p, f_q, f_pq] per node (field_grid.h)
  double tail_a0_ = 0.0;                      // mean of A on r = r_max
  std::vector<std::complex<double>> tail_;    // c_n = a_n + i b_n, n = 1..K
};

} // namespace magbrush
