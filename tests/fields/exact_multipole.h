// Exact exterior field of radially magnetised rings in air — the reference for the
// interpolator tests and the benchmark (written here on purpose: the tests must not depend
// on the production multipole module they might one day be compared with).
//
// A ring R_i < r < R_o with M_r = M cos(n(θ − φ)), μr = 1, has outside r > R_o
//   B_x − i B_y = μ0 n E_n e^{inφ} z^{−(n+1)},   E_n = M R_o^{n+1} (1 − ρ^{n+1}) / (2(n+1)),
// ρ = R_i/R_o (the 2D field of a magnetised ring, from its surface and volume pole densities). With B = curl(A ẑ) and A = Re G(z), B_x − i B_y = i G'(z), so
//   G(z) = i μ0 E_n e^{inφ} z^{−n},   A = μ0 E_n r^{−n} sin(n(θ − φ)).
// The test suite checks B = curl A numerically, so a slip in this derivation would show.
#pragma once

#include <array>
#include <cmath>
#include <algorithm>
#include <complex>
#include <random>
#include <vector>

namespace magbrush::testing {

constexpr double mu0 = 4e-7 * M_PI;

struct RingTerm
{
  int n;        // harmonic order
  double M;     // amplitude [A/m]
  double phase; // φ [rad]
};

struct FieldAndGradient
{
  std::array<double, 2> B;                   // [T]
  std::array<std::array<double, 2>, 2> gradB; // ∂B_i/∂x_j [T/m]
};

// A sum of ring terms, evaluated through G(z) = Σ_n k_n z^{−n}, k_n = i μ0 E_n e^{inφ}
// (powers by recurrence: fast enough to sample fine grids of a 60-term roller).
class MultipoleField
{
public:
  MultipoleField(double R_i, double R_o, std::vector<RingTerm> terms)
    : R_i_(R_i), R_o_(R_o), terms_(std::move(terms))
  {
    int n_max = 0;
    for (const auto &t : terms_)
      n_max = std::max(n_max, t.n);
    k_.assign(n_max + 1, 0.0);
    for (const auto &t : terms_)
      k_[t.n] += std::complex<double>(0.0, mu0 * E(t)) * std::polar(1.0, t.n * t.phase);
  }

  double E(const RingTerm &t) const
  {
    const double rho = R_i_ / R_o_;
    return t.M * std::pow(R_o_, t.n + 1) * (1.0 - std::pow(rho, t.n + 1)) / (2.0 * (t.n + 1));
  }

  // A_z = Re G(z) [T·m].
  double A(double x, double y) const
  {
    const std::complex<double> w = 1.0 / std::complex<double>(x, y);
    std::complex<double> wn = 1.0, G = 0.0;
    for (size_t n = 1; n < k_.size(); ++n)
    {
      wn *= w;
      G += k_[n] * wn;
    }
    return G.real();
  }

  // B_x − i B_y = i G'(z), and its derivatives d/dx = d/dz, d/dy = i d/dz.
  FieldAndGradient B(double x, double y) const
  {
    const std::complex<double> w = 1.0 / std::complex<double>(x, y);
    const std::complex<double> w2 = w * w;
    std::complex<double> wn = 1.0, G1 = 0.0, G2 = 0.0;
    for (size_t n = 1; n < k_.size(); ++n)
    {
      wn *= w; // w^n
      const double dn = static_cast<double>(n);
      G1 += -dn * k_[n] * wn * w;           // −n k_n z^{−n−1}
      G2 += dn * (dn + 1) * k_[n] * wn * w2; // n(n+1) k_n z^{−n−2}
    }
    const std::complex<double> I(0.0, 1.0);
    return from_complex(I * G1, I * G2);
  }

  // The field formula above, term by term: B_x − i B_y = μ0 n E_n e^{inφ} z^{−(n+1)}
  // (independent of G: the tests compare curl A with this).
  FieldAndGradient B_design_formula(double x, double y) const
  {
    const std::complex<double> z(x, y);
    std::complex<double> f = 0.0, df = 0.0;
    for (const auto &t : terms_)
    {
      const std::complex<double> k = mu0 * t.n * E(t) * std::polar(1.0, t.n * t.phase);
      f += k * std::pow(z, -(t.n + 1));
      df += -(t.n + 1.0) * k * std::pow(z, -(t.n + 2));
    }
    return from_complex(f, df);
  }

private:
  // From f = B_x − i B_y and df = df/dz.
  static FieldAndGradient from_complex(std::complex<double> f, std::complex<double> df)
  {
    FieldAndGradient out;
    out.B = {f.real(), -f.imag()};
    const std::complex<double> dfy = std::complex<double>(0, 1) * df;
    out.gradB = {{{df.real(), dfy.real()}, {-df.imag(), -dfy.imag()}}};
    return out;
  }

  double R_i_, R_o_;
  std::vector<RingTerm> terms_;
  std::vector<std::complex<double>> k_; // k_n, index n
};

// Fourier series of the Gaussian pole model M_r(θ) = Σ_i M_i exp(−α wrap(θ − φ_i)²) as ring
// terms n = 1..n_max (the n = 0 term has no exterior field).
inline std::vector<RingTerm> gaussian_poles_as_rings(const std::vector<std::array<double, 2>> &poles,
                                                     double alpha, int n_max)
{
  const int N = 4096;
  std::vector<double> m(N, 0.0);
  for (int j = 0; j < N; ++j)
  {
    const double th = 2 * M_PI * j / N;
    for (const auto &[phi, M] : poles)
    {
      const double d = std::remainder(th - phi, 2 * M_PI);
      m[j] += M * std::exp(-alpha * d * d);
    }
  }
  std::vector<RingTerm> terms;
  for (int n = 1; n <= n_max; ++n)
  {
    double a = 0.0, b = 0.0;
    for (int j = 0; j < N; ++j)
    {
      const double th = 2 * M_PI * j / N;
      a += m[j] * std::cos(n * th);
      b += m[j] * std::sin(n * th);
    }
    a *= 2.0 / N;
    b *= 2.0 / N;
    // a cos nθ + b sin nθ = |c| cos(n(θ − φ)) with n φ = atan2(b, a).
    terms.push_back({n, std::hypot(a, b), std::atan2(b, a) / n});
  }
  return terms;
}

// The roller of the benchmark and of the accuracy tests: the 5-pole roller of
// cases/data/sleeve_profile_example.csv scaled to a 12.5 mm sleeve (magnet ring
// 3.75..11.625 mm in air, α = 10 /rad², poles S1 0° −330, N1 72° 172, S2 144° −200,
// S3 216° −170, N2 288° 142 kA/m). A larger α makes sharper poles (more harmonics).
inline MultipoleField roller_like_field(double alpha = 10.0)
{
  const double deg = M_PI / 180.0;
  const std::vector<std::array<double, 2>> poles = {
      {0 * deg, -330e3}, {72 * deg, 172e3}, {144 * deg, -200e3}, {216 * deg, -170e3}, {288 * deg, 142e3}};
  return MultipoleField(3.75e-3, 11.625e-3, gaussian_poles_as_rings(poles, alpha, 80));
}

// Points spread uniformly over the annulus r_min ≤ r ≤ r_max (fixed seed).
inline std::vector<std::array<double, 2>> sample_annulus(double r_min, double r_max, int count,
                                                         unsigned seed = 12345)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::array<double, 2>> points(count);
  for (auto &p : points)
  {
    const double r = std::sqrt(r_min * r_min + u(rng) * (r_max * r_max - r_min * r_min));
    const double th = 2 * M_PI * u(rng);
    p = {r * std::cos(th), r * std::sin(th)};
  }
  return points;
}

} // namespace magbrush::testing
