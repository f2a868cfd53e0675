// B and ∇B from the spline of A_z on the polar grid; the multipole tail beyond it.
#include "fields/polar_field_interpolator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace magbrush {

namespace {
constexpr double two_pi = 2.0 * M_PI;
}

PolarFieldInterpolator::PolarFieldInterpolator(const PolarGrid &grid, int tail_harmonics)
  : r_min_(grid.r_min), r_max_(grid.r_max), dr_(0), dtheta_(0), n_r_(grid.n_r),
    n_theta_(grid.n_theta)
{
  validate(grid, "PolarFieldInterpolator");
  dr_ = grid.dr();
  dtheta_ = grid.dtheta();
  inv_dr_ = 1.0 / dr_;
  inv_dtheta_ = 1.0 / dtheta_;
  nodes_ = spline::bicubic_hermite_data(grid.A_z, n_r_, n_theta_, /*periodic θ*/ true);

  // Fourier coefficients of A on the outer ring (the trigonometric interpolant of its nodes).
  const int N = n_theta_;
  const int n_max = std::min(128, (N - 1) / 2);
  const double *ring = &grid.A_z[static_cast<size_t>(n_r_ - 1) * N];
  tail_a0_ = 0.0;
  for (int j = 0; j < N; ++j)
    tail_a0_ += ring[j];
  tail_a0_ /= N;
  std::vector<std::complex<double>> c(n_max);
  for (int n = 1; n <= n_max; ++n)
  {
    double a = 0.0, b = 0.0;
    for (int j = 0; j < N; ++j)
    {
      const double phase = two_pi * static_cast<double>((static_cast<long>(n) * j) % N) / N;
      a += ring[j] * std::cos(phase);
      b += ring[j] * std::sin(phase);
    }
    c[n - 1] = {2.0 * a / N, 2.0 * b / N};
  }
  int K = n_max;
  if (tail_harmonics >= 0)
    K = std::min(tail_harmonics, n_max);
  else
  {
    // Smallest K whose omitted amplitude is negligible against the whole.
    double total = 0.0;
    for (const auto &cn : c)
      total += std::abs(cn);
    double omitted = total;
    K = 0;
    while (K < n_max && omitted > 1e-8 * total)
      omitted -= std::abs(c[K++]);
  }
  tail_.assign(c.begin(), c.begin() + K);
}

size_t PolarFieldInterpolator::memory_bytes() const
{
  return nodes_.size() * sizeof(double) + tail_.size() * sizeof(std::complex<double>);
}

PolarFieldInterpolator::Potential PolarFieldInterpolator::from_grid(double x, double y,
                                                                    double r) const
{
  // Cell and local coordinates: p along r, q along θ (periodic). locate() guarantees
  // s ≥ −1/2, where truncation gives cell 0 and p < 0 (the boundary cell's extension).
  const double s = (r - r_min_) * inv_dr_;
  int i = static_cast<int>(s);
  i = i > n_r_ - 2 ? n_r_ - 2 : i;
  const double p = s - i;
  double theta = std::atan2(y, x);
  theta += theta < 0 ? two_pi : 0.0;
  const double u = theta * inv_dtheta_;
  int j = static_cast<int>(u);
  j = j >= n_theta_ ? n_theta_ - 1 : j;
  const double q = u - j;
  const int j1 = j + 1 == n_theta_ ? 0 : j + 1;

  const double *row0 = &nodes_[static_cast<size_t>(i) * n_theta_ * 4];
  const double *row1 = row0 + static_cast<size_t>(n_theta_) * 4;
  double f[6];
  spline::evaluate_patch(row0 + 4 * j, row0 + 4 * j1, row1 + 4 * j, row1 + 4 * j1, p, q, f);

  // Polar derivatives, then the chain rule to Cartesian (c = cos θ, sn = sin θ).
  const double A_r = f[1] * inv_dr_, A_t = f[2] * inv_dtheta_;
  const double A_rr = f[3] * inv_dr_ * inv_dr_, A_rt = f[4] * inv_dr_ * inv_dtheta_,
               A_tt = f[5] * inv_dtheta_ * inv_dtheta_;
  const double inv_r = 1.0 / r, c = x * inv_r, sn = y * inv_r;
  const double cc = c * c, ss = sn * sn, cs = c * sn;
  const double A_t_r = A_t * inv_r, A_rt_r = A_rt * inv_r, A_t_rr = A_t_r * inv_r,
               A_tt_rr = A_tt * inv_r * inv_r, A_r_r = A_r * inv_r;
  Potential P;
  P.A = f[0];
  P.A_x = c * A_r - sn * A_t_r;
  P.A_y = sn * A_r + c * A_t_r;
  P.A_xx = cc * A_rr - 2 * cs * A_rt_r + 2 * cs * A_t_rr + ss * A_r_r + ss * A_tt_rr;
  P.A_yy = ss * A_rr + 2 * cs * A_rt_r - 2 * cs * A_t_rr + cc * A_r_r + cc * A_tt_rr;
  P.A_xy = cs * A_rr + (cc - ss) * A_rt_r - (cc - ss) * A_t_rr - cs * A_r_r - cs * A_tt_rr;
  return P;
}

// A = Re G(z), G(z) = a_0 + Σ c_n t^n with t = r_max/z: analytic, so the field is harmonic.
// G' = −S1/z, G'' = S2/z² with S1 = Σ n c_n t^n, S2 = Σ n(n+1) c_n t^n; A_x − i A_y = G'.
PolarFieldInterpolator::Potential PolarFieldInterpolator::from_tail(double x, double y) const
{
  // t = r_max / z = r_max z̄ / |z|²; complex products written out (std::complex's operator*
  // guards against NaN/Inf and is several times slower).
  const double inv_r2 = 1.0 / (x * x + y * y);
  const double tr = r_max_ * x * inv_r2, ti = -r_max_ * y * inv_r2;
  double pr = 1.0, pi = 0.0; // t^n
  double S0r = 0, S0i = 0, S1r = 0, S1i = 0, S2r = 0, S2i = 0;
  const size_t K = tail_.size();
  for (size_t k = 0; k < K; ++k)
  {
    const double n = static_cast<double>(k + 1);
    const double npr = pr * tr - pi * ti;
    pi = pr * ti + pi * tr;
    pr = npr;
    const double cr = tail_[k].real(), ci = tail_[k].imag();
    const double termr = cr * pr - ci * pi, termi = cr * pi + ci * pr;
    S0r += termr;
    S0i += termi;
    S1r += n * termr;
    S1i += n * termi;
    S2r += n * (n + 1) * termr;
    S2i += n * (n + 1) * termi;
  }
  // 1/z = z̄/|z|², 1/z² = z̄²/|z|⁴.
  const double izr = x * inv_r2, izi = -y * inv_r2;
  const double iz2r = izr * izr - izi * izi, iz2i = 2 * izr * izi;
  const double G1r = -(S1r * izr - S1i * izi), G1i = -(S1r * izi + S1i * izr);
  const double G2r = S2r * iz2r - S2i * iz2i, G2i = S2r * iz2i + S2i * iz2r;
  Potential P;
  P.A = tail_a0_ + S0r;
  P.A_x = G1r;
  P.A_y = -G1i;
  // G'' = A_xx − i A_xy, and A_yy = −A_xx (harmonic).
  P.A_xx = G2r;
  P.A_xy = -G2i;
  P.A_yy = -G2r;
  return P;
}

void PolarFieldInterpolator::throw_inside_sleeve(const Vec3 &x, double r) const
{
  std::ostringstream m;
  m.precision(6);
  if (!std::isfinite(r))
  {
    m << "magnetic field lookup at a non-finite position (" << x[0] << ", " << x[1] << ", "
      << x[2] << "): the particle state has blown up (NaN/Inf) — reduce the time step";
    throw FieldLookupError(m.str());
  }
  m << "magnetic field lookup at (" << x[0] << ", " << x[1] << ", " << x[2]
    << ") m: radius " << r << " m lies inside the field grid's inner radius " << r_min_
    << " m (the sleeve surface); a particle there has penetrated the sleeve — reduce the time "
       "step or check the contact stiffness";
  throw FieldLookupError(m.str());
}

namespace {
// B = (A_y, −A_x, 0); ∂B_x/∂x_j = (A_xy, A_yy), ∂B_y/∂x_j = (−A_xx, −A_xy).
template <typename P>
void field_and_gradient(const P &a, Vec3 &B, std::array<Vec3, 3> &gradB)
{
  B = {a.A_y, -a.A_x, 0.0};
  gradB[0] = {a.A_xy, a.A_yy, 0.0};
  gradB[1] = {-a.A_xx, -a.A_xy, 0.0};
  gradB[2] = {0.0, 0.0, 0.0};
}
} // namespace

void PolarFieldInterpolator::evaluate(const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &gradB) const
{
  const double r = std::sqrt(x[0] * x[0] + x[1] * x[1]);
  switch (locate(r))
  {
  case Where::grid:
    field_and_gradient(from_grid(x[0], x[1], r), B, gradB);
    return;
  case Where::tail:
    field_and_gradient(from_tail(x[0], x[1]), B, gradB);
    return;
  case Where::inside_sleeve:
    throw_inside_sleeve(x, r);
  }
}

bool PolarFieldInterpolator::try_evaluate(const Vec3 &x, Vec3 &B,
                                          std::array<Vec3, 3> &gradB) const noexcept
{
  const double r = std::sqrt(x[0] * x[0] + x[1] * x[1]);
  switch (locate(r))
  {
  case Where::grid:
    field_and_gradient(from_grid(x[0], x[1], r), B, gradB);
    return true;
  case Where::tail:
    field_and_gradient(from_tail(x[0], x[1]), B, gradB);
    return true;
  case Where::inside_sleeve:
    break;
  }
  B = {0.0, 0.0, 0.0};
  gradB = {};
  return false;
}

Vec3 PolarFieldInterpolator::field(const Vec3 &x) const
{
  Vec3 B;
  std::array<Vec3, 3> gradB;
  evaluate(x, B, gradB);
  return B;
}

double PolarFieldInterpolator::vector_potential(const Vec3 &x) const
{
  const double r = std::sqrt(x[0] * x[0] + x[1] * x[1]);
  switch (locate(r))
  {
  case Where::grid:
    return from_grid(x[0], x[1], r).A;
  case Where::tail:
    return from_tail(x[0], x[1]).A;
  case Where::inside_sleeve:
    break;
  }
  throw_inside_sleeve(x, r);
}

} // namespace magbrush
