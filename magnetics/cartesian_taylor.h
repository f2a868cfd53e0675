// Cartesian Taylor expansions of the magnetic scalar potential of point dipoles: the
// operators of the cell-multipole far field (P2M, M2M, M2L, L2L, L2P).
//
// A dipole p at y has the scalar potential φ(x) = −(1/4π) p·∇G(x − y), G(r) = 1/|r|, and
// the field B = −μ0 ∇φ. About a source-cell centre c (s = y − c, R = x − c),
//
//   φ(x) = −(1/4π) Σ_β M_β D_β(R),   D_β = ∂^β G,
//   M_β  = Σ_dipoles Σ_{i: β_i ≥ 1} p_i (−s)^(β−e_i) / (β−e_i)!,      1 ≤ |β| ≤ P,
//
// (the moments of a dipole distribution are those of the equivalent charges: no monopole).
// About a target-cell centre t (x = t + u) the potential is a Taylor series
//
//   φ(t + u) = −(1/4π) Σ_γ L_γ u^γ/γ!,   L_γ = Σ_β M_β D_(β+γ)(t − c),   1 ≤ |γ| ≤ Q,
//
// so B_a = (μ0/4π) Σ_γ L_(γ+e_a) u^γ/γ! and ∂_b B_a = (μ0/4π) Σ_γ L_(γ+e_a+e_b) u^γ/γ!.
// The derivatives D_α of 1/r follow from the recurrence (n = |α|)
//
//   n r² D_α = −(2n − 1) Σ_i α_i x_i D_(α−e_i) − (n − 1) Σ_i α_i (α_i − 1) D_(α−2e_i).
//
// Expansion order p: P = p + 1 (p = 0: the cell's total dipole only), Q = p + 2 (so that
// the field gradient at a bead is a Taylor polynomial of degree p across the target cell).
#pragma once

#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class CartesianTaylor
{
public:
  explicit CartesianTaylor(int order);

  int order() const { return order_; }
  int multipole_order() const { return P_; } // P
  int local_order() const { return Q_; }     // Q
  std::size_t multipole_size() const { return n_multipole_; } // number of β, 1 ≤ |β| ≤ P
  std::size_t local_size() const { return n_local_; }         // number of γ, 1 ≤ |γ| ≤ Q
  std::size_t derivative_size() const { return n_derivative_; } // number of α, 0 ≤ |α| ≤ P+Q
  // Position of the multi-index (a, b, c) in the derivative table (a + b + c ≤ P + Q).
  int index(int a, int b, int c) const { return idx(a, b, c); }

  // D_α(x) = ∂^α (1/|x|) for all |α| ≤ P + Q (indexed like the multi-index table).
  void derivatives(const double x[3], double *D) const;

  // Adds the moments of one dipole p at offset s = y − c from the cell centre.
  void add_dipole(const double s[3], const double p[3], double *M) const;
  // Adds a child's moments (centre c') to the parent's (centre c), d = c' − c (exact shift).
  void shift_multipole(const double d[3], const double *M_child, double *M_parent) const;
  // Adds L_γ += Σ_β M_β D_(β+γ) (D evaluated at t − c).
  void multipole_to_local(const double *D, const double *M, double *L) const;
  // The same translation as a dense matrix A[γ][β] = D_(β+γ) (local_size × multipole_size):
  // tabulated once per cell offset, applied as a matrix-vector product (vectorises).
  void translation_matrix(const double *D, double *A) const;
  // Single precision (the translation matrices and moments rounded to float, each row
  // summed in float, added to the double local coefficients): relative rounding ~1e-7 per
  // translation against an expansion error of ~1e-3; twice the SIMD width.
  // Single precision: lengths are scaled by s (the level's cell size) so that high-order
  // tensors stay within float range: A'[β][γ] = A s^(|β|+|γ|+1) stored transposed (β-major),
  // M'_β = M_β s^(−|β|); a target cell sums all its translations into float coefficients
  // L' (vectorised over γ), and L_γ += s^(−|γ|−1) L'_γ at the end (row_scales).
  void accumulate_translation(const float *At, const float *M, float *Lf) const
  {
    const std::size_t nm = n_multipole_, nl = n_local_;
    for (std::size_t b = 0; b < nm; ++b)
    {
      const float m = M[b];
      const float *column = At + b * nl;
#pragma omp simd
      for (std::size_t g = 0; g < nl; ++g)
        Lf[g] += column[g] * m;
    }
  }
  void scaled_matrix(const double *A, double s, float *Af) const;
  void scaled_moments(const double *M, double s, float *Mf) const;
  void row_scales(double s, double *row_scale) const;
  void apply_translation(const double *A, const double *M, double *L) const
  {
    const std::size_t nm = n_multipole_, nl = n_local_;
    for (std::size_t g = 0; g < nl; ++g)
    {
      const double *row = A + g * nm;
      double sum = 0.0;
#pragma omp simd reduction(+ : sum)
      for (std::size_t b = 0; b < nm; ++b)
        sum += row[b] * M[b];
      L[g] += sum;
    }
  }
  // Adds the parent's local expansion (centre t) re-centred at the child centre t' = t + e.
  void shift_local(const double e[3], const double *L_parent, double *L_child) const;
  // Field B [T] and gradient gradB[a][b] = ∂B_a/∂x_b at u = x − t, ADDED.
  void evaluate(const double u[3], const double *L, double B[3], double gradB[3][3]) const;

private:
  int order_, P_, Q_, K_;
  std::size_t n_multipole_ = 0, n_local_ = 0, n_derivative_ = 0;
  // Multi-index table up to order K = P + Q: exponents, and the index of (a, b, c).
  std::vector<std::uint8_t> ex_, ey_, ez_;
  std::vector<int> index_; // (K+1)³ lookup, −1 when a + b + c > K
  std::vector<double> inv_factorial_; // 1/α! per multi-index
  int idx(int a, int b, int c) const { return index_[(a * (K_ + 1) + b) * (K_ + 1) + c]; }
  // Monomials w_ν = v^ν/ν! for |ν| ≤ order (indexed like the table).
  void monomials(const double v[3], int order, double *w) const;
  // Flattened operator tables (index triples), built once.
  struct Term { std::uint16_t out, in, coeff; };
  std::vector<Term> m2l_;          // L[out] += M[in] D[coeff]
  std::vector<Term> m2m_;          // M_parent[out] += M_child[in] w[coeff]
  std::vector<Term> l2l_;          // L_child[out] += L_parent[in] w[coeff]
  std::vector<Term> p2m_;          // M[out] += p_(in) w[coeff]  (in = component 0..2)
  std::vector<Term> l2p_field_;    // g_(out) += L[in] w[coeff]  (out = component a)
  std::vector<Term> l2p_gradient_; // H_(out) += L[in] w[coeff]  (out = 3a + b)
};

} // namespace magbrush::magnetics
