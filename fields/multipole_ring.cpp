// The exact multipole-ring solution (see multipole_ring.h for the derivation).
#include "fields/multipole_ring.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace {
constexpr double mu0 = 4e-7 * M_PI; // the field solver uses the same (pre-2019 exact) value
constexpr double pi = M_PI;

} // namespace

// ---------------------------------------------------------------------------------------
// Geometry

RingGeometry RingGeometry::from(const Roller &roller)
{
  RingGeometry g;
  g.shaft_radius = roller.shaft_radius;
  g.shaft_mu_r = (std::isinf(roller.shaft_mu_r) || roller.shaft_mu_r >= 1e12) ? ideal_iron
                                                                             : roller.shaft_mu_r;
  g.magnet_radius = roller.magnet_radius;
  g.magnet_mu_r = roller.magnet_mu_r;
  g.validate();
  return g;
}

void RingGeometry::validate() const
{
  std::ostringstream msg;
  if (!(magnet_radius > 0.0))
    msg << "the magnet radius must be positive (found " << magnet_radius
        << " m); set roller.magnet_radius";
  else if (!(shaft_radius >= 0.0) || shaft_radius >= magnet_radius)
    msg << "the shaft radius must lie in [0, magnet radius) = [0, " << magnet_radius
        << ") m (found " << shaft_radius << " m); set roller.shaft_radius (0 = no shaft)";
  else if (!(magnet_mu_r > 0.0) || std::isinf(magnet_mu_r))
    msg << "the magnet's recoil permeability must be a positive finite number (found "
        << magnet_mu_r << "); typical ferrite/NdFeB values are 1.05–1.1";
  else if (!(shaft_mu_r > 0.0))
    msg << "the shaft permeability must be positive (found " << shaft_mu_r
        << "); use a large value or infinity for ideal iron";
  const std::string m = msg.str();
  if (!m.empty())
    throw std::invalid_argument("multipole ring: " + m);
}

// ---------------------------------------------------------------------------------------
// Fourier coefficients of one Gaussian pole

int GaussianPoleSpectrum::default_samples(int harmonics)
{
  int k = 2048;
  while (k < 16 * harmonics)
    k *= 2;
  return k;
}

GaussianPoleSpectrum GaussianPoleSpectrum::compute(double alpha, int harmonics, int samples)
{
  if (!(alpha > 0.0))
    throw std::invalid_argument("Gaussian pole: the shape factor α must be positive (found " +
                                std::to_string(alpha) + " 1/rad²)");
  GaussianPoleSpectrum s;
  s.g.assign(harmonics + 1, 0.0);
  s.dg_da.assign(harmonics + 1, 0.0);
  // Periodic trapezoid on u_k = −π + 2πk/K. The shape is even, so only cosines survive; the
  // powers e^{inu} come from a rotation recurrence (K·N complex products, no trig in the loop).
  const double du = 2.0 * pi / samples;
  for (int k = 0; k < samples; ++k)
  {
    const double u = -pi + k * du;
    const double w = std::exp(-alpha * u * u);
    const double dw = -u * u * w;
    const std::complex<double> step(std::cos(u), std::sin(u));
    std::complex<double> z(1.0, 0.0);
    s.g[0] += w;
    s.dg_da[0] += dw;
    for (int n = 1; n <= harmonics; ++n)
    {
      z *= step;
      s.g[n] += w * z.real();
      s.dg_da[n] += dw * z.real();
    }
  }
  s.g[0] /= samples;
  s.dg_da[0] /= samples;
  for (int n = 1; n <= harmonics; ++n)
  {
    s.g[n] *= 2.0 / samples;
    s.dg_da[n] *= 2.0 / samples;
  }
  return s;
}

std::vector<MagnetisationHarmonic> MultipoleRing::pole_harmonics(const std::vector<Pole> &poles,
                                                                 int harmonics)
{
  std::vector<MagnetisationHarmonic> h(harmonics);
  for (int n = 1; n <= harmonics; ++n)
    h[n - 1].n = n;
  const int samples = GaussianPoleSpectrum::default_samples(harmonics);
  for (const Pole &pole : poles)
  {
    const auto s = GaussianPoleSpectrum::compute(pole.shape_factor, harmonics, samples);
    // M exp(−α wrap(θ − φ)²) = M Σ g_n cos n(θ − φ) = M Σ g_n (cos nφ cos nθ + sin nφ sin nθ)
    for (int n = 1; n <= harmonics; ++n)
    {
      h[n - 1].a += pole.strength * s.g[n] * std::cos(n * pole.angle);
      h[n - 1].b += pole.strength * s.g[n] * std::sin(n * pole.angle);
    }
  }
  return h;
}

HarmonicChoice MultipoleRing::choose_harmonics(const std::vector<Pole> &poles,
                                               const Options &options)
{
  if (poles.empty())
    throw std::invalid_argument("multipole ring: the roller has no poles; add roller.poles");
  // Start from the decay of the narrowest pole, e^(−n²/4α): N ≈ 2 √(α ln(1/tol)); then check
  // the actual coefficients up to twice that and grow until the tail is below tolerance.
  double alpha_max = 0.0;
  for (const Pole &p : poles)
    alpha_max = std::max(alpha_max, p.shape_factor);
  const double log_tol = std::log(1.0 / options.relative_tolerance);
  int probe = static_cast<int>(std::ceil(2.0 * std::sqrt(alpha_max * log_tol))) + 8;
  HarmonicChoice choice;
  for (;;)
  {
    probe = std::min(probe, options.max_harmonics);
    const auto h = pole_harmonics(poles, probe);
    double largest = 0.0;
    for (const auto &c : h)
      largest = std::max(largest, std::hypot(c.a, c.b));
    int last = 0;
    for (int i = 0; i < probe; ++i)
      if (std::hypot(h[i].a, h[i].b) > options.relative_tolerance * largest)
        last = i + 1;
    const bool resolved = last < probe - 4; // a few negligible terms beyond the last one
    if (resolved || probe == options.max_harmonics)
    {
      choice.harmonics = std::max(last, 1);
      choice.capped = !resolved;
      choice.tail = 0.0;
      for (int i = choice.harmonics; i < probe; ++i)
        choice.tail = std::max(choice.tail, std::hypot(h[i].a, h[i].b) / largest);
      return choice;
    }
    probe *= 2;
  }
}

// ---------------------------------------------------------------------------------------
// One harmonic: the 4×4 interface system (dimensionless, lengths in units of R_m).
//
// Bases normalised at their own boundaries (ρ = r/R_m, σ = R_s/R_m):
//   shaft  f = s (ρ/σ)^n,   magnet f = P(ρ) + p ρ^n + q (σ/ρ)^n,   air f = d ρ^−n.

MultipoleRing::HarmonicResponse::HarmonicResponse(const RingGeometry &geometry, int n)
    : g_(geometry), n_(n), sigma_(geometry.shaft_radius / geometry.magnet_radius), s_(0), p_(0),
      q_(0), d_(0)
{
  if (n < 1)
    throw std::invalid_argument("multipole ring: harmonic order must be ≥ 1 (found " +
                                std::to_string(n) + ")");
  const double mu_m = g_.magnet_mu_r;
  const double nn = n;
  const bool has_shaft = sigma_ > 0.0;
  const bool ideal = std::isinf(g_.shaft_mu_r);
  const double sn = has_shaft ? std::pow(sigma_, nn) : 0.0; // σ^n (may underflow: harmless)

  // Unknowns x = (p, q, d, s). Rows: ψ and B_r at ρ = 1, then at ρ = σ.
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  // ψ continuous at ρ = 1:  p + q σ^n − d = −P(1)
  A(0, 0) = 1.0;
  A(0, 1) = sn;
  A(0, 2) = -1.0;
  rhs(0) = -particular(1.0);
  // B_r continuous at ρ = 1: −μ_m (P' + n p − n q σ^n) + 1 = n d
  A(1, 0) = -mu_m * nn;
  A(1, 1) = mu_m * nn * sn;
  A(1, 2) = -nn;
  rhs(1) = mu_m * particular_derivative(1.0) - 1.0;
  if (!has_shaft)
  {
    // The magnet fills the disc: the r^−n term would be singular at the centre.
    A(2, 1) = 1.0; // q = 0
    A(3, 3) = 1.0; // s = 0
  }
  else if (ideal)
  {
    // Ideal iron: H = 0 inside, so ψ is constant on the shaft (zero for n ≥ 1).
    A(2, 0) = sn;
    A(2, 1) = 1.0;
    rhs(2) = -particular(sigma_);
    A(3, 3) = 1.0; // s unused
  }
  else
  {
    const double mu_s = g_.shaft_mu_r;
    // ψ continuous at ρ = σ: p σ^n + q − s = −P(σ)
    A(2, 0) = sn;
    A(2, 1) = 1.0;
    A(2, 3) = -1.0;
    rhs(2) = -particular(sigma_);
    // B_r continuous at ρ = σ (multiplied by σ): μ_m n p σ^n − μ_m n q − μ_s n s = σ(1 − μ_m P'(σ))
    A(3, 0) = mu_m * nn * sn;
    A(3, 1) = -mu_m * nn;
    A(3, 3) = -mu_s * nn;
    rhs(3) = sigma_ * (1.0 - mu_m * particular_derivative(sigma_));
  }
  const Eigen::Vector4d x = A.fullPivLu().solve(rhs);
  p_ = x(0);
  q_ = x(1);
  d_ = x(2);
  s_ = x(3);
}

// Particular solution of μ_m ∇²f = 1/ρ for the source cos nθ (dimensionless).
double MultipoleRing::HarmonicResponse::particular(double rho) const
{
  const double mu_m = g_.magnet_mu_r;
  if (n_ == 1)
    return rho > 0.0 ? rho * std::log(rho) / (2.0 * mu_m) : 0.0;
  return rho / (mu_m * (1.0 - double(n_) * n_));
}

double MultipoleRing::HarmonicResponse::particular_derivative(double rho) const
{
  const double mu_m = g_.magnet_mu_r;
  if (n_ == 1)
    return (std::log(rho) + 1.0) / (2.0 * mu_m);
  return 1.0 / (mu_m * (1.0 - double(n_) * n_));
}

double MultipoleRing::HarmonicResponse::exterior_factor(double r) const
{
  return n_ * d_ * std::pow(g_.magnet_radius / r, n_ + 1);
}

void MultipoleRing::HarmonicResponse::radial_factors(double r, double &beta_r,
                                                     double &beta_theta) const
{
  const double rho = r / g_.magnet_radius;
  const double nn = n_;
  if (rho >= 1.0)
  {
    radial_factors_from_powers(rho, 0.0, 0.0, std::pow(1.0 / rho, nn + 1.0), beta_r, beta_theta);
    return;
  }
  if (rho >= sigma_)
  {
    // The very centre of a shaftless magnet: the field depends on the direction of approach
    // (M_r is discontinuous there), so evaluate just off it.
    const double x = std::max(rho, 1e-300);
    radial_factors_from_powers(x, std::pow(x, nn - 1.0), sigma_ > 0.0 ? std::pow(sigma_ / x, nn) : 0.0,
                               0.0, beta_r, beta_theta);
    return;
  }
  // Inside the shaft: ψ = c r^n, so β_r = B (r/R_s)^(n−1), β_θ = −β_r, with B = β_r at the
  // shaft surface (B_r is continuous). For ideal iron that is the μ_s → ∞ limit.
  double br_surface, bt_surface;
  if (std::isinf(g_.shaft_mu_r))
    radial_factors_from_powers(sigma_, std::pow(sigma_, nn - 1.0), 1.0, 0.0, br_surface, bt_surface);
  else
    br_surface = -g_.shaft_mu_r * nn * s_ / sigma_;
  beta_r = br_surface * std::pow(rho / sigma_, nn - 1.0);
  beta_theta = -beta_r;
}

void MultipoleRing::HarmonicResponse::radial_factors_from_powers(double x, double up, double down,
                                                                 double out, double &beta_r,
                                                                 double &beta_theta) const
{
  const double nn = n_;
  if (x >= 1.0)
  {
    beta_r = beta_theta = nn * d_ * out; // air: f = d x^−n
    return;
  }
  // Magnet: f = P + p x^n + q (σ/x)^n,  f' = P' + n p x^(n−1) − n q σ^n x^(−n−1)
  const double mu_m = g_.magnet_mu_r;
  const double p_up = p_ * up;                              // p x^(n−1)
  const double q_down = sigma_ > 0.0 ? q_ * down / x : 0.0; // q σ^n x^(−n−1)
  const double f = particular(x) + x * p_up + x * q_down;
  const double df = particular_derivative(x) + nn * p_up - nn * q_down;
  beta_r = -mu_m * df + 1.0;
  beta_theta = mu_m * nn * f / x;
}

void MultipoleRing::radial_factors_at(double r, std::vector<double> &fr, std::vector<double> &ft) const
{
  const size_t N = harmonics_.size();
  fr.resize(N);
  ft.resize(N);
  const double rho = r / geometry_.magnet_radius;
  const double sigma = geometry_.shaft_radius / geometry_.magnet_radius;
  if (!consecutive_ || rho < sigma)
  {
    for (size_t i = 0; i < N; ++i)
      responses_[i].radial_factors(r, fr[i], ft[i]);
    return;
  }
  // Orders 1, 2, 3, ...: the powers x^(n−1), (σ/x)^n, (1/x)^(n+1) by recurrence.
  const double x = std::max(rho, 1e-300);
  double up = 1.0, down = sigma / x, out = 1.0 / (x * x);
  for (size_t i = 0; i < N; ++i)
  {
    responses_[i].radial_factors_from_powers(x, up, down, out, fr[i], ft[i]);
    if (x < 1.0)
    {
      up *= x;
      down *= sigma / x;
    }
    else
      out /= x;
  }
}

// ---------------------------------------------------------------------------------------
// The roller

MultipoleRing::MultipoleRing(const Roller &roller, const Options &options)
    : geometry_(RingGeometry::from(roller))
{
  for (const Pole &p : roller.poles)
    if (!(p.shape_factor > 0.0))
      throw std::invalid_argument("multipole ring: pole '" + p.name +
                                  "' has a non-positive shape factor " +
                                  std::to_string(p.shape_factor) + "; α must be > 0 [1/rad²]");
  if (options.harmonics > 0)
    choice_.harmonics = options.harmonics;
  else
    choice_ = choose_harmonics(roller.poles, options);
  harmonics_ = pole_harmonics(roller.poles, choice_.harmonics);
  const int samples = GaussianPoleSpectrum::default_samples(1);
  for (const Pole &p : roller.poles)
    mean_magnetisation_ += p.strength * GaussianPoleSpectrum::compute(p.shape_factor, 0, samples).g[0];
  build_responses();
}

MultipoleRing::MultipoleRing(const RingGeometry &geometry,
                             const std::vector<MagnetisationHarmonic> &harmonics)
    : geometry_(geometry)
{
  geometry_.validate();
  for (const auto &h : harmonics)
    if (h.n >= 1)
      harmonics_.push_back(h);
    else if (h.n == 0)
      mean_magnetisation_ += h.a;
  choice_.harmonics = static_cast<int>(harmonics_.size());
  build_responses();
}

void MultipoleRing::build_responses()
{
  consecutive_ = true;
  for (size_t i = 0; i < harmonics_.size(); ++i)
    consecutive_ = consecutive_ && harmonics_[i].n == static_cast<int>(i) + 1;
  responses_.clear();
  responses_.reserve(harmonics_.size());
  for (const auto &h : harmonics_)
    responses_.emplace_back(geometry_, h.n);
}

RingField MultipoleRing::field(double x, double y) const
{
  return field_polar(std::hypot(x, y), std::atan2(y, x));
}

RingField MultipoleRing::field_polar(double r, double theta) const
{
  RingField f;
  std::vector<double> fr, ft;
  radial_factors_at(r, fr, ft);
  const std::complex<double> step = std::polar(1.0, theta);
  std::complex<double> z(1.0, 0.0); // e^{inθ} by recurrence when the orders are 1, 2, 3, ...
  for (size_t i = 0; i < harmonics_.size(); ++i)
  {
    const auto &h = harmonics_[i];
    const double br = fr[i], bt = ft[i];
    z = consecutive_ ? z * step : std::polar(1.0, h.n * theta);
    const double c = z.real(), s = z.imag();
    f.Br += br * (h.a * c + h.b * s);
    f.Btheta += bt * (h.a * s - h.b * c);
    f.Az += (r * br / h.n) * (h.a * s - h.b * c);
  }
  f.Br *= mu0;
  f.Btheta *= mu0;
  f.Az *= mu0;
  const double c = std::cos(theta), s = std::sin(theta);
  f.Bx = f.Br * c - f.Btheta * s;
  f.By = f.Br * s + f.Btheta * c;
  return f;
}

void MultipoleRing::profile(double r, const std::vector<double> &angles, std::vector<double> &Bn,
                            std::vector<double> &Bt) const
{
  const size_t N = harmonics_.size();
  std::vector<double> fr, ft;
  radial_factors_at(r, fr, ft);
  Bn.assign(angles.size(), 0.0);
  Bt.assign(angles.size(), 0.0);
  for (size_t k = 0; k < angles.size(); ++k)
  {
    double bn = 0.0, bt = 0.0;
    const std::complex<double> step = std::polar(1.0, angles[k]);
    std::complex<double> z(1.0, 0.0);
    for (size_t i = 0; i < N; ++i)
    {
      const auto &h = harmonics_[i];
      z = consecutive_ ? z * step : std::polar(1.0, h.n * angles[k]);
      const double c = z.real(), s = z.imag();
      bn += fr[i] * (h.a * c + h.b * s);
      bt += ft[i] * (h.a * s - h.b * c);
    }
    Bn[k] = mu0 * bn;
    Bt[k] = mu0 * bt;
  }
}

double MultipoleRing::magnetisation(double theta) const
{
  double m = mean_magnetisation_;
  for (const auto &h : harmonics_)
    m += h.a * std::cos(h.n * theta) + h.b * std::sin(h.n * theta);
  return m;
}

} // namespace magbrush
