// Cartesian Taylor expansions of the potential of point sources — charges (1/r) or dipoles —
// the operators of the cell-multipole far field (P2M, M2M, M2L, L2L, L2P). The source kind is
// fixed per expansion: it decides whether the moments start at the monopole.
//
// All expansions rest on G(r) = 1/|r| and its derivatives D_α = ∂^α G. About a source-cell
// centre c (s = y − c, R = x − c) and a target-cell centre t (x = t + u),
//
//   1/|R − s| = Σ_β (−s)^β/β! D_β(R),
//   Σ_β M_β D_β(t + u − c) = Σ_γ L_γ u^γ/γ!,   L_γ = Σ_β M_β D_(β+γ)(t − c).
//
// SourceKind::dipoles (the induced magnetic dipoles). A dipole p at y has the magnetic
// scalar potential φ(x) = −(1/4π) p·∇G(x − y) and the field B = −μ0 ∇φ:
//
//   φ(x) = −(1/4π) Σ_β M_β D_β(R),
//   M_β  = Σ_dipoles Σ_{i: β_i ≥ 1} p_i (−s)^(β−e_i) / (β−e_i)!,      1 ≤ |β| ≤ P,
//
// (the moments of a dipole distribution are those of the equivalent charges: no monopole),
// locals 1 ≤ |γ| ≤ Q, and B_a = (μ0/4π) Σ_γ L_(γ+e_a) u^γ/γ!,
// ∂_b B_a = (μ0/4π) Σ_γ L_(γ+e_a+e_b) u^γ/γ! (evaluate()). Order p: P = p + 1 (p = 0: the
// cell's total dipole only), Q = p + 2 (the field gradient at a bead is a Taylor polynomial
// of degree p across the target cell).
//
// SourceKind::charges (point charges, optionally with dipoles: the electrostatics). The
// expansion is of the kernel sum Φ(x) = Σ_j q_j/|x − y_j| + Σ_j p_j·(x − y_j)/|x − y_j|³,
//
//   Φ(x) = Σ_β M_β D_β(R),
//   M_β  = Σ_charges q (−s)^β/β! − Σ_dipoles Σ_i p_i (−s)^(β−e_i)/(β−e_i)!,   0 ≤ |β| ≤ P,
//
// locals 0 ≤ |γ| ≤ Q, and evaluate_potential() returns Φ, ∇Φ and ∇∇Φ at u (no physical
// prefactor: the field of charges in SI units is E = −∇Φ/(4πε0)). Order p: P = p,
// Q = p + 1 (the field is a Taylor polynomial of degree p across the target cell).
//
// The derivatives D_α of 1/r follow from the recurrence (n = |α|)
//
//   n r² D_α = −(2n − 1) Σ_i α_i x_i D_(α−e_i) − (n − 1) Σ_i α_i (α_i − 1) D_(α−2e_i).
#pragma once

#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

// What the sources of an expansion are: dipoles only (moments from order 1, the magnetic
// convention above), or charges (moments from order 0; dipoles may be added as well).
enum class SourceKind { dipoles, charges };

class CartesianTaylor
{
public:
  explicit CartesianTaylor(int order, SourceKind kind = SourceKind::dipoles);

  SourceKind source_kind() const { return kind_; }
  int order() const { return order_; }
  int multipole_order() const { return P_; } // P
  int local_order() const { return Q_; }     // Q
  // Number of β (resp. γ) with first ≤ |β| ≤ P (resp. Q); first = 1 for dipoles, 0 for charges.
  std::size_t multipole_size() const { return n_multipole_; }
  std::size_t local_size() const { return n_local_; }
  std::size_t derivative_size() const { return n_derivative_; } // number of α, 0 ≤ |α| ≤ P+Q
  // Position of the multi-index (a, b, c) in the derivative table (a + b + c ≤ P + Q).
  int index(int a, int b, int c) const { return idx(a, b, c); }

  // D_α(x) = ∂^α (1/|x|) for all |α| ≤ P + Q (indexed like the multi-index table).
  void derivatives(const double x[3], double *D) const;

  // Adds the moments of one dipole p at offset s = y − c from the cell centre (in the
  // convention of the source kind: a charges expansion adds −p, see above).
  void add_dipole(const double s[3], const double p[3], double *M) const;
  // Adds the moments of one charge q at offset s (charges only).
  void add_charge(const double s[3], double q, double *M) const;
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
  // Dipoles: field B [T] and gradient gradB[a][b] = ∂B_a/∂x_b at u = x − t, ADDED.
  void evaluate(const double u[3], const double *L, double B[3], double gradB[3][3]) const;
  // Charges: Φ, ∇Φ (3) and ∇∇Φ (9, row-major) of the kernel sum at u = x − t, ADDED; any
  // pointer may be null.
  void evaluate_potential(const double u[3], const double *L, double *phi, double *grad,
                          double *hessian) const;

private:
  SourceKind kind_;
  int order_, P_, Q_, K_;
  int first_ = 1; // lowest moment / local order (1 dipoles, 0 charges): M, L store index − first_
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
  std::vector<Term> p2m_charge_;   // M[out] += q w[coeff]  (charges)
  std::vector<Term> l2p_potential_; // Φ += L[in] w[coeff]  (charges)
  std::vector<Term> l2p_field_;    // g_(out) += L[in] w[coeff]  (out = component a)
  std::vector<Term> l2p_gradient_; // H_(out) += L[in] w[coeff]  (out = 3a + b)
};

} // namespace magbrush::magnetics
