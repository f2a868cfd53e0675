#include "magnetics/two_sphere_exact.h"

#include "magnetics/dipole_physics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

namespace {

// Legendre P_l(x) and P_l'(x) for l = 0..L (the derivative by P'_{l+1} = P'_{l−1} + (2l+1) P_l,
// which stays accurate at the poles).
void legendre(int L, double x, std::vector<double> &P, std::vector<double> &dP)
{
  P.assign(L + 2, 0.0);
  dP.assign(L + 2, 0.0);
  P[0] = 1.0;
  P[1] = x;
  dP[1] = 1.0;
  for (int l = 1; l <= L; ++l)
  {
    P[l + 1] = ((2 * l + 1) * x * P[l] - l * P[l - 1]) / (l + 1);
    dP[l + 1] = dP[l - 1] + (2 * l + 1) * P[l];
  }
}

// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_N from Chebyshev guesses).
void gauss_legendre(int N, std::vector<double> &x, std::vector<double> &w)
{
  x.resize(N);
  w.resize(N);
  std::vector<double> P, dP;
  for (int k = 0; k < N; ++k)
  {
    double t = std::cos(pi * (k + 0.75) / (N + 0.5));
    for (int it = 0; it < 100; ++it)
    {
      legendre(N, t, P, dP);
      const double step = P[N] / dP[N];
      t -= step;
      if (std::abs(step) < 1e-16)
        break;
    }
    legendre(N, t, P, dP);
    x[k] = t;
    w[k] = 2.0 / ((1.0 - t * t) * dP[N] * dP[N]);
  }
}

// log of (l+n)! / ((l+m)! (n−m)!) / d^(l+n+1): the size of a re-expansion coefficient.
double log_translation(int l, int n, int m, double d)
{
  return std::lgamma(l + n + 1.0) - std::lgamma(l + m + 1.0) - std::lgamma(n - m + 1.0) -
         (l + n + 1.0) * std::log(d);
}

// γ_l = l(μ − 1)/(lμ + l + 1) a^(2l+1): the response of a sphere to an incident order-l field.
double response(int l, double mu, double a)
{
  return l * (mu - 1.0) / (l * mu + l + 1.0) * std::pow(a, 2 * l + 1);
}

} // namespace

TwoSphereSeries::TwoSphereSeries(const TwoSphereGeometry &geometry, int m, int orders)
  : s_(geometry.a1), g_(geometry), m_(m), L_(orders)
{
  if (m != 0 && m != 1)
    throw std::invalid_argument("two-sphere series: expected azimuthal order m = 0 or 1, found " +
                                std::to_string(m) + ".");
  if (orders < 1)
    throw std::invalid_argument("two-sphere series: expected at least one order, found " +
                                std::to_string(orders) + ".");
  if (!(g_.a1 > 0 && g_.a2 > 0 && g_.d >= (g_.a1 + g_.a2) * (1 - 1e-12)))
    throw std::invalid_argument("two-sphere series: expected positive radii and a centre distance "
                                "≥ a1 + a2 (non-overlapping spheres); found a1 = " +
                                std::to_string(g_.a1) + ", a2 = " + std::to_string(g_.a2) +
                                ", d = " + std::to_string(g_.d) + ".");
  g_.a1 /= s_;
  g_.a2 /= s_;
  g_.d /= s_;
  const int L = L_;
  const double d = g_.d;
  // Unknowns x = (A_1..A_L, B_1..B_L);  M x = b;  dM = ∂M/∂d.
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(2 * L, 2 * L);
  Eigen::MatrixXd dM = Eigen::MatrixXd::Zero(2 * L, 2 * L);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(2 * L);
  // Applied potential −H0 z (m = 0) or −H0 x (m = 1): −r P_1^m(cos θ) cos mϕ about either
  // centre (up to a constant), i.e. an incident order-1 coefficient of −1.
  b(0) = response(1, g_.mu1, g_.a1);
  b(L) = response(1, g_.mu2, g_.a2);
  for (int l = 1; l <= L; ++l)
  {
    const double g1 = response(l, g_.mu1, g_.a1), g2 = response(l, g_.mu2, g_.a2);
    for (int n = 1; n <= L; ++n)
    {
      const double t = std::exp(log_translation(l, n, m, d));
      const double t12 = ((n + m) % 2 ? -t : t); // sphere 2's order n about centre 1
      const double t21 = ((l + m) % 2 ? -t : t); // sphere 1's order n about centre 2
      M(l - 1, L + n - 1) = g1 * t12;
      M(L + l - 1, n - 1) = g2 * t21;
      dM(l - 1, L + n - 1) = -(l + n + 1.0) / d * g1 * t12;
      dM(L + l - 1, n - 1) = -(l + n + 1.0) / d * g2 * t21;
    }
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(M);
  const Eigen::VectorXd x = lu.solve(b);
  const Eigen::VectorXd dx = lu.solve(-(dM * x));

  A_.assign(L + 1, 0.0);
  B_.assign(L + 1, 0.0);
  for (int l = 1; l <= L; ++l)
  {
    A_[l] = x(l - 1);
    B_[l] = x(L + l - 1);
  }
  dA1_ = dx(0);
  dB1_ = dx(L);

  // Regular (incident) expansion about centre 2: the applied field and sphere 1's multipoles.
  E2_.assign(L + 1, 0.0);
  E2_[1] = -1.0;
  for (int l = 1; l <= L; ++l)
    for (int n = 1; n <= L; ++n)
    {
      const double t = std::exp(log_translation(l, n, m, d));
      E2_[l] += ((l + m) % 2 ? -t : t) * A_[n];
    }
}

void TwoSphereSeries::field_near_sphere2(double r, double theta, double phi, double H[3]) const
{
  r /= s_;
  const double x = std::cos(theta), s = std::sin(theta);
  std::vector<double> P, dP;
  legendre(L_, x, P, dP);
  double Hr = 0.0, Ht = 0.0, Hp = 0.0;
  double rl = 1.0, rm = 1.0 / r; // r^l and r^−(l+1), updated as l grows
  for (int l = 1; l <= L_; ++l)
  {
    rl *= r;
    rm /= r;
    const double c = E2_[l] * rl + B_[l] * rm;
    const double dc = l * E2_[l] * rl / r - (l + 1) * B_[l] * rm / r;
    if (m_ == 0)
    {
      Hr -= dc * P[l];
      Ht += c / r * s * dP[l]; // −(1/r) c dP_l/dθ, dP_l/dθ = −sin θ P_l'
    }
    else
    {
      const double P1 = s * dP[l];                       // P_l^1 (no Condon–Shortley phase)
      const double dP1 = l * (l + 1.0) * P[l] - x * dP[l]; // dP_l^1/dθ
      Hr -= dc * P1 * std::cos(phi);
      Ht -= c / r * dP1 * std::cos(phi);
      Hp += c / r * dP[l] * std::sin(phi); // P_l^1 / sin θ = P_l'
    }
  }
  const double cp = std::cos(phi), sp = std::sin(phi);
  H[0] = Hr * s * cp + Ht * x * cp - Hp * sp;
  H[1] = Hr * s * sp + Ht * x * sp + Hp * cp;
  H[2] = Hr * x - Ht * s;
}

TwoSphereForce two_sphere_force_energy(const TwoSphereGeometry &g, int orders)
{
  const TwoSphereSeries along(g, 0, orders), across(g, 1, orders);
  TwoSphereForce f;
  f.parallel = 2.0 * pi * along.dipole_sum_derivative();
  f.perpendicular = 2.0 * pi * across.dipole_sum_derivative();
  f.transverse = -4.0 * pi * (along.dipole_sum() - across.dipole_sum()) / g.d;
  f.orders = orders;
  return f;
}

TwoSphereForce two_sphere_force_stress(const TwoSphereGeometry &g, int orders, double R)
{
  if (R <= 0.0)
    R = g.a2;
  const TwoSphereSeries along(g, 0, orders), across(g, 1, orders);
  std::vector<double> xq, wq;
  gauss_legendre(2 * orders + 16, xq, wq);
  const int nphi = 8; // the stress is a trigonometric polynomial of degree ≤ 3 in ϕ
  // ∮ [H (H·n) − ½ H² n] dS for the field along (ψ = 0), across (ψ = π/2) and at ψ = π/4.
  double Fz_along = 0.0, Fz_across = 0.0, Fx_mixed = 0.0;
  for (std::size_t q = 0; q < xq.size(); ++q)
  {
    const double theta = std::acos(xq[q]);
    for (int k = 0; k < nphi; ++k)
    {
      const double phi = 2.0 * pi * k / nphi;
      const double n[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                           std::cos(theta)};
      double H0[3], H1[3], Hm[3];
      along.field_near_sphere2(R, theta, phi, H0);
      across.field_near_sphere2(R, theta, phi, H1);
      for (int c = 0; c < 3; ++c)
        Hm[c] = (H0[c] + H1[c]) / std::sqrt(2.0);
      auto traction = [&](const double *H, int c) {
        const double Hn = H[0] * n[0] + H[1] * n[1] + H[2] * n[2];
        const double H2 = H[0] * H[0] + H[1] * H[1] + H[2] * H[2];
        return H[c] * Hn - 0.5 * H2 * n[c];
      };
      const double dS = wq[q] * (2.0 * pi / nphi) * R * R;
      Fz_along += traction(H0, 2) * dS;
      Fz_across += traction(H1, 2) * dS;
      Fx_mixed += traction(Hm, 0) * dS;
    }
  }
  TwoSphereForce f;
  f.parallel = Fz_along;
  f.perpendicular = Fz_across;
  // At ψ = π/4 the field leans toward +x, so growing ψ moves sphere 2 toward −x:
  // F_x = −f_t sinψ cosψ = −f_t / 2.
  f.transverse = -2.0 * Fx_mixed;
  f.orders = orders;
  return f;
}

TwoSphereForce two_sphere_force(const TwoSphereGeometry &g, double rel_tol, int max_orders)
{
  int L = 8;
  TwoSphereForce previous = two_sphere_force_energy(g, L);
  while (true)
  {
    const int next = std::min(max_orders, static_cast<int>(std::ceil(1.5 * L)));
    if (next == L)
      throw std::runtime_error(
        "two-sphere series: not converged to " + std::to_string(rel_tol) + " within " +
        std::to_string(max_orders) + " orders at d/a1 = " + std::to_string(g.d / g.a1) +
        ", μ = " + std::to_string(g.mu1) + "; raise max_orders or loosen the tolerance.");
    const TwoSphereForce f = two_sphere_force_energy(g, next);
    const double scale = std::abs(f.parallel);
    const double change = std::max({std::abs(f.parallel - previous.parallel),
                                    std::abs(f.perpendicular - previous.perpendicular),
                                    std::abs(f.transverse - previous.transverse)});
    L = next;
    previous = f;
    if (change <= rel_tol * scale)
      return f;
  }
}

TwoSphereForce point_dipole_pair_force(double a, double beta, double d)
{
  const double D = d / a, c = pi * beta * beta * a * a / (D * D * D * D);
  return {-24.0 * c, 12.0 * c, -24.0 * c, 0};
}

TwoSphereForce mutual_dipole_pair_force(double a, double beta, double d)
{
  const double D3 = std::pow(d / a, 3);
  const double along = 1.0 / (1.0 - 2.0 * beta / D3), across = 1.0 / (1.0 + beta / D3);
  TwoSphereForce f = point_dipole_pair_force(a, beta, d);
  f.parallel *= along * along;
  f.perpendicular *= across * across;
  f.transverse *= along * across;
  return f;
}

} // namespace magbrush::magnetics
