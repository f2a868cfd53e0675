#include "magnetics/cartesian_taylor.h"

#include "magnetics/dipole_physics.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

CartesianTaylor::CartesianTaylor(int order, SourceKind kind)
  : kind_(kind), order_(order), P_(kind == SourceKind::dipoles ? order + 1 : order),
    Q_(kind == SourceKind::dipoles ? order + 2 : order + 1), first_(kind == SourceKind::dipoles ? 1 : 0)
{
  if (order < 0 || order > 6)
    throw std::invalid_argument("cell multipole: expected an expansion order 0–6, found " +
                                std::to_string(order) + ".");
  K_ = P_ + Q_;
  // Multi-indices ordered by total order, then lexicographically: index 0 is (0,0,0), the
  // orders first..P (resp. first..Q) are the contiguous indices first..N, so that M and L
  // store index − first.
  index_.assign((K_ + 1) * (K_ + 1) * (K_ + 1), -1);
  for (int n = 0; n <= K_; ++n)
    for (int a = n; a >= 0; --a)
      for (int b = n - a; b >= 0; --b)
      {
        const int c = n - a - b;
        index_[(a * (K_ + 1) + b) * (K_ + 1) + c] = static_cast<int>(ex_.size());
        ex_.push_back(static_cast<std::uint8_t>(a));
        ey_.push_back(static_cast<std::uint8_t>(b));
        ez_.push_back(static_cast<std::uint8_t>(c));
        double f = 1.0;
        for (int k = 2; k <= a; ++k) f *= k;
        for (int k = 2; k <= b; ++k) f *= k;
        for (int k = 2; k <= c; ++k) f *= k;
        inv_factorial_.push_back(1.0 / f);
        if (n == P_ && a == 0 && b == 0)
          n_multipole_ = ex_.size() - first_;
        if (n == Q_ && a == 0 && b == 0)
          n_local_ = ex_.size() - first_;
      }
  n_derivative_ = ex_.size();

  auto u16 = [](int v) { return static_cast<std::uint16_t>(v); };
  const int unit[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::size_t first = static_cast<std::size_t>(first_);
  for (std::size_t t = first; t < n_derivative_; ++t)
  {
    const int a = ex_[t], b = ey_[t], c = ez_[t], n = a + b + c;
    if (n <= P_)
    {
      // P2M: M_β += p_i w_(β−e_i)(−s) (dipoles), M_β += q w_β(−s) (charges).
      for (int i = 0; i < 3; ++i)
      {
        const int ra = a - unit[i][0], rb = b - unit[i][1], rc = c - unit[i][2];
        if (ra >= 0 && rb >= 0 && rc >= 0)
          p2m_.push_back({u16(t - first), u16(i), u16(idx(ra, rb, rc))});
      }
      if (kind_ == SourceKind::charges)
        p2m_charge_.push_back({u16(t - first), 0, u16(t)});
      // M2M: M_β += M'_β' w_(β−β')(−d), β' ≤ β, |β'| ≥ first.
      for (std::size_t s = first; s < first + n_multipole_; ++s)
        if (ex_[s] <= a && ey_[s] <= b && ez_[s] <= c)
          m2m_.push_back({u16(t - first), u16(s - first), u16(idx(a - ex_[s], b - ey_[s], c - ez_[s]))});
    }
    if (n <= Q_)
    {
      // M2L: L_γ += M_β D_(β+γ).
      for (std::size_t s = first; s < first + n_multipole_; ++s)
        m2l_.push_back({u16(t - first), u16(s - first), u16(idx(a + ex_[s], b + ey_[s], c + ez_[s]))});
      // L2L: L'_γ' += L_γ w_(γ−γ')(e), γ ≥ γ' (here t = γ', s = γ).
      for (std::size_t s = first; s < first + n_local_; ++s)
        if (ex_[s] >= a && ey_[s] >= b && ez_[s] >= c)
          l2l_.push_back({u16(t - first), u16(s - first), u16(idx(ex_[s] - a, ey_[s] - b, ez_[s] - c))});
    }
  }
  // L2P: g_a += L_(γ+e_a) w_γ(u), |γ| ≤ Q − 1;  H_ab += L_(γ+e_a+e_b) w_γ(u), |γ| ≤ Q − 2;
  // charges also Φ += L_γ w_γ(u), |γ| ≤ Q.
  for (std::size_t g = 0; g < n_derivative_; ++g)
  {
    const int a = ex_[g], b = ey_[g], c = ez_[g], n = a + b + c;
    for (int i = 0; i < 3 && n <= Q_ - 1; ++i)
      l2p_field_.push_back({u16(i), u16(idx(a + unit[i][0], b + unit[i][1], c + unit[i][2]) - first_), u16(g)});
    for (int i = 0; i < 3 && n <= Q_ - 2; ++i)
      for (int j = 0; j < 3; ++j)
        l2p_gradient_.push_back({u16(3 * i + j),
                                 u16(idx(a + unit[i][0] + unit[j][0], b + unit[i][1] + unit[j][1],
                                         c + unit[i][2] + unit[j][2]) - first_),
                                 u16(g)});
    if (kind_ == SourceKind::charges && n <= Q_)
      l2p_potential_.push_back({0, u16(g), u16(g)});
  }
}

void CartesianTaylor::derivatives(const double x[3], double *D) const
{
  const double r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
  const double inv_r2 = 1.0 / r2;
  D[0] = std::sqrt(inv_r2);
  for (std::size_t t = 1; t < n_derivative_; ++t)
  {
    const int e[3] = {ex_[t], ey_[t], ez_[t]};
    const int n = e[0] + e[1] + e[2];
    double sum = 0.0;
    for (int i = 0; i < 3; ++i)
    {
      if (e[i] == 0)
        continue;
      int m1[3] = {e[0], e[1], e[2]};
      --m1[i];
      sum += (2 * n - 1) * e[i] * x[i] * D[idx(m1[0], m1[1], m1[2])];
      if (e[i] >= 2)
      {
        --m1[i];
        sum += (n - 1) * e[i] * (e[i] - 1) * D[idx(m1[0], m1[1], m1[2])];
      }
    }
    D[t] = -sum * inv_r2 / n;
  }
}

void CartesianTaylor::monomials(const double v[3], int order, double *w) const
{
  w[0] = 1.0;
  for (std::size_t t = 1; t < n_derivative_; ++t)
  {
    const int a = ex_[t], b = ey_[t], c = ez_[t];
    if (a + b + c > order)
      break;
    if (a > 0)
      w[t] = w[idx(a - 1, b, c)] * v[0] / a;
    else if (b > 0)
      w[t] = w[idx(a, b - 1, c)] * v[1] / b;
    else
      w[t] = w[idx(a, b, c - 1)] * v[2] / c;
  }
}

void CartesianTaylor::add_dipole(const double s[3], const double p[3], double *M) const
{
  double w[1024];
  const double v[3] = {-s[0], -s[1], -s[2]};
  monomials(v, P_ - 1, w);
  if (kind_ == SourceKind::charges) // Φ of a dipole is p·∇_y(1/|x − y|): the moments of −p
  {
    for (const Term &term : p2m_)
      M[term.out] -= p[term.in] * w[term.coeff];
    return;
  }
  for (const Term &term : p2m_)
    M[term.out] += p[term.in] * w[term.coeff];
}

void CartesianTaylor::add_charge(const double s[3], double q, double *M) const
{
  double w[1024];
  const double v[3] = {-s[0], -s[1], -s[2]};
  monomials(v, P_, w);
  for (const Term &term : p2m_charge_)
    M[term.out] += q * w[term.coeff];
}

void CartesianTaylor::shift_multipole(const double d[3], const double *M_child,
                                      double *M_parent) const
{
  double w[1024];
  const double v[3] = {-d[0], -d[1], -d[2]};
  monomials(v, P_ - first_, w);
  for (const Term &term : m2m_)
    M_parent[term.out] += M_child[term.in] * w[term.coeff];
}

void CartesianTaylor::multipole_to_local(const double *D, const double *M, double *L) const
{
  for (const Term &term : m2l_)
    L[term.out] += M[term.in] * D[term.coeff];
}

void CartesianTaylor::translation_matrix(const double *D, double *A) const
{
  for (const Term &term : m2l_)
    A[term.out * n_multipole_ + term.in] = D[term.coeff];
}

void CartesianTaylor::scaled_matrix(const double *A, double s, float *Af) const
{
  for (std::size_t g = 0; g < n_local_; ++g)
    for (std::size_t b = 0; b < n_multipole_; ++b)
    {
      const std::size_t gi = g + first_, bi = b + first_;
      const int n = ex_[gi] + ey_[gi] + ez_[gi] + ex_[bi] + ey_[bi] + ez_[bi] + 1;
      Af[b * n_local_ + g] = static_cast<float>(A[g * n_multipole_ + b] * std::pow(s, n));
    }
}

void CartesianTaylor::scaled_moments(const double *M, double s, float *Mf) const
{
  for (std::size_t b = 0; b < n_multipole_; ++b)
  {
    const std::size_t bi = b + first_;
    Mf[b] = static_cast<float>(M[b] * std::pow(s, -(ex_[bi] + ey_[bi] + ez_[bi])));
  }
}

void CartesianTaylor::row_scales(double s, double *row_scale) const
{
  for (std::size_t g = 0; g < n_local_; ++g)
  {
    const std::size_t gi = g + first_;
    row_scale[g] = std::pow(s, -(ex_[gi] + ey_[gi] + ez_[gi] + 1));
  }
}

void CartesianTaylor::shift_local(const double e[3], const double *L_parent, double *L_child) const
{
  double w[1024];
  monomials(e, Q_ - first_, w);
  for (const Term &term : l2l_)
    L_child[term.out] += L_parent[term.in] * w[term.coeff];
}

void CartesianTaylor::evaluate(const double u[3], const double *L, double B[3],
                               double gradB[3][3]) const
{
  double w[1024];
  monomials(u, Q_ - 1, w);
  double g[3] = {0.0, 0.0, 0.0}, H[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (const Term &term : l2p_field_)
    g[term.out] += L[term.in] * w[term.coeff];
  for (const Term &term : l2p_gradient_)
    H[term.out] += L[term.in] * w[term.coeff];
  const double c = mu0 / (4.0 * pi);
  for (int a = 0; a < 3; ++a)
  {
    B[a] += c * g[a];
    for (int b = 0; b < 3; ++b)
      gradB[a][b] += c * H[3 * a + b];
  }
}

void CartesianTaylor::evaluate_potential(const double u[3], const double *L, double *phi,
                                         double *grad, double *hessian) const
{
  double w[1024];
  monomials(u, Q_, w);
  if (phi)
    for (const Term &term : l2p_potential_)
      *phi += L[term.in] * w[term.coeff];
  if (grad)
    for (const Term &term : l2p_field_)
      grad[term.out] += L[term.in] * w[term.coeff];
  if (hessian)
    for (const Term &term : l2p_gradient_)
      hessian[term.out] += L[term.in] * w[term.coeff];
}

} // namespace magbrush::magnetics
