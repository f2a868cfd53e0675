// The exact field of the Gaussian-pole magnet roller: a layered cylinder solved harmonic by
// harmonic (the "multipole ring"). It is the reference the finite-element field solver is
// verified against and the fast forward model of the pole fit.
//
// Geometry (roller frame: centre at the origin, angles counter-clockwise from +x):
//
//      r < R_s          shaft, relative permeability μ_s (R_s = 0: no shaft;
//                       μ_s = ∞: ideal iron, H = 0 inside, the potential is constant on it)
//      R_s < r < R_m    magnet, recoil permeability μ_m, radial magnetisation M_r(θ)
//      r > R_m          non-magnetic (μ = 1; the sleeve is aluminium)
//
// with B = μ0 (μ H + M) and M = M_r(θ) r̂ in the magnet only. Any M_r(θ) is a Fourier series
//
//      M_r(θ) = m_0 + Σ_{n≥1} (a_n cos nθ + b_n sin nθ),
//
// and the problem is linear and rotation-invariant, so each harmonic can be solved on its own.
// With no free currents H = −∇ψ and ∇·B = 0 gives μ ∇²ψ = ∇·M = M_r / r in each layer. For the
// unit source M_r = cos nθ the potential is ψ = f_n(r) cos nθ with
//
//      shaft:  f = s r^n            magnet: f = P_n(r) + p r^n + q r^−n       air: f = d r^−n
//
// where P_n is the particular solution of the source term (r/(μ_m (1 − n²)) for n ≥ 2,
// r ln r /(2 μ_m) for n = 1). The interface conditions — ψ continuous (H_θ continuous) and
// B_r = μ0(−μ ∂ψ/∂r + M_r) continuous — fix s, p, q, d (a 4×4 system per harmonic). The n = 0
// term (uniform radial magnetisation) produces no field at all: r B_r would be a net flux out
// of every circle, which must vanish, and H_θ would need a net current. So only n ≥ 1 counts.
//
// Fields of the unit harmonic, with χ = 1 in the magnet and 0 elsewhere:
//
//      B_r = μ0 β_r(r) cos nθ,   β_r = −μ f'(r) + χ
//      B_θ = μ0 β_θ(r) sin nθ,   β_θ = μ n f(r) / r
//      A_z = μ0 (r β_r / n) sin nθ        (B = ∇ × (A_z ẑ): B_r = (1/r) ∂A/∂θ)
//
// (a sin nθ source gives the same with θ shifted by π/(2n)). Outside the magnet β_r = β_θ =
// n d r^−n−1 and, for μ = 1 everywhere, d reduces to the classical ring result
// E_n = M R_o^(n+1) (1 − ρ^(n+1)) / (2(n+1)), ρ = R_i/R_o (B_x − i B_y = μ0 n E_n z^−(n+1)).
//
// Lengths are made dimensionless by R_m before solving, and the layer bases are normalised at
// their own boundaries ((r/R_m)^n, (R_s/r)^n, (R_m/r)^n), so no power ever overflows even for
// thousands of harmonics.
#pragma once

#include "case/case_model.h"

#include <limits>
#include <vector>

namespace magbrush {

// The layered cylinder (all radii in m).
struct RingGeometry
{
  static constexpr double ideal_iron = std::numeric_limits<double>::infinity();

  double shaft_radius = 0.0;   // R_s; 0 = no shaft (the magnet fills the disc)
  double shaft_mu_r = 1.0;     // μ_s; RingGeometry::ideal_iron = the μ_s → ∞ limit
  double magnet_radius = 0.0;  // R_m
  double magnet_mu_r = 1.0;    // μ_m (recoil permeability)

  // From the case. An infinite (or ≥ 1e12) Roller::shaft_mu_r selects the ideal-iron limit.
  static RingGeometry from(const Roller &roller);
  void validate() const; // throws std::invalid_argument with what is wrong and what to do
};

// The field at one point. Polar components use the local (r̂, θ̂) frame: B_r is the normal
// flux density on a circle (positive outward), B_θ the tangential one (positive CCW).
struct RingField
{
  double Br = 0, Btheta = 0; // [T]
  double Bx = 0, By = 0;     // [T]
  double Az = 0;             // [T m], gauge: A_z → 0 far away
};

// One Fourier term of the radial magnetisation: a cos nθ + b sin nθ [A/m].
struct MagnetisationHarmonic
{
  int n = 1;
  double a = 0.0, b = 0.0;
};

// Fourier coefficients of one Gaussian pole shape exp(−α wrap(u)²) (u ∈ (−π, π]), which is even:
// g_n = (1/π) ∫ exp(−α u²) cos nu du (n ≥ 1), g_0 = the mean. Computed by the trapezoidal rule
// on `samples` points, spectrally accurate for this smooth periodic function (the kink at
// u = ±π has size ~α e^(−απ²) and costs O(kink/samples²)). Also dg_n/dα for the fit.
struct GaussianPoleSpectrum
{
  std::vector<double> g;      // g[0..N]
  std::vector<double> dg_da;  // ∂g_n/∂α
  static GaussianPoleSpectrum compute(double alpha, int harmonics, int samples);
  static int default_samples(int harmonics); // ≥ 16 per harmonic, ≥ 2048, power of two
};

// Choice of the number of harmonics for a pole set: the smallest N such that every
// coefficient of the magnetisation beyond N is below `relative_tolerance` × the largest one.
// `max_harmonics` caps it (very wide poles, α ≲ 3, have a slope kink at the back and an
// algebraically decaying series; the field outside the magnet still converges geometrically).
struct HarmonicChoice
{
  int harmonics = 0;
  double tail = 0.0;       // largest |coefficient| beyond `harmonics`, relative to the largest
  bool capped = false;     // true if max_harmonics was reached before the tolerance
};

class MultipoleRing
{
public:
  struct Options
  {
    int harmonics = 0;                 // 0 = choose from the decay of the coefficients
    double relative_tolerance = 1e-14; // for the automatic choice
    int max_harmonics = 1024;
  };

  // The Gaussian-pole roller of the case.
  MultipoleRing(const Roller &roller, const Options &options);
  explicit MultipoleRing(const Roller &roller) : MultipoleRing(roller, Options()) {}
  // Any magnetisation given by its harmonics (n ≥ 1; n = 0 makes no field and is ignored).
  MultipoleRing(const RingGeometry &geometry, const std::vector<MagnetisationHarmonic> &harmonics);

  // Field at a point in the roller frame (x, y [m]); valid everywhere except exactly on r = 0
  // when there is no shaft and a dipole (n = 1) term is present (log singularity).
  RingField field(double x, double y) const;
  RingField field_polar(double r, double theta) const;

  // Normal (B_r) and tangential (B_θ) flux density on the circle of radius r at the given
  // angles [rad] — the gaussmeter's view. Fast path outside the magnet.
  void profile(double r, const std::vector<double> &angles, std::vector<double> &Bn,
               std::vector<double> &Bt) const;

  // Magnetisation M_r(θ) as represented by the truncated series (for checking the expansion).
  double magnetisation(double theta) const;

  const RingGeometry &geometry() const { return geometry_; }
  int harmonic_count() const { return static_cast<int>(harmonics_.size()); }
  const HarmonicChoice &harmonic_choice() const { return choice_; }

  // The unit response of harmonic n (source M_r = cos nθ of 1 A/m) in dimensionless form:
  // radial factors β_r(r), β_θ(r) such that B_r = μ0 β_r cos nθ, B_θ = μ0 β_θ sin nθ.
  // Exposed for the pole fit and the tests.
  class HarmonicResponse
  {
  public:
    HarmonicResponse(const RingGeometry &geometry, int n);
    int n() const { return n_; }
    void radial_factors(double r, double &beta_r, double &beta_theta) const;
    // The same outside the shaft (x = r/R_m ≥ R_s/R_m) with the powers supplied by the caller:
    // up = x^(n−1), down = (σ/x)^n (σ = R_s/R_m), out = (1/x)^(n+1) — so that consecutive
    // harmonics at one radius cost a multiplication each instead of a pow().
    void radial_factors_from_powers(double x, double up, double down, double out, double &beta_r,
                                    double &beta_theta) const;
    // Exterior coefficient d_n in units of M R_m^(n+1): outside, β = n d_n (R_m/r)^(n+1).
    // For μ = 1 everywhere this is the classical E_n/(M R_o^(n+1)).
    double exterior_coefficient() const { return d_; }
    double exterior_factor(double r) const; // n d_n (R_m/r)^(n+1)

  private:
    RingGeometry g_;
    int n_;
    double sigma_;        // R_s / R_m
    double s_, p_, q_, d_; // coefficients of the normalised bases (see the .cpp)
    double particular(double rho) const;
    double particular_derivative(double rho) const;
  };

  const std::vector<HarmonicResponse> &responses() const { return responses_; }
  const std::vector<MagnetisationHarmonic> &harmonics() const { return harmonics_; }

  // Pick the harmonic count for a set of poles (see HarmonicChoice).
  static HarmonicChoice choose_harmonics(const std::vector<Pole> &poles, const Options &options);
  // Fourier coefficients of Σ_i M_i exp(−α_i wrap(θ − φ_i)²), n = 1..N.
  static std::vector<MagnetisationHarmonic> pole_harmonics(const std::vector<Pole> &poles,
                                                           int harmonics);

private:
  RingGeometry geometry_;
  std::vector<MagnetisationHarmonic> harmonics_;
  std::vector<HarmonicResponse> responses_;
  double mean_magnetisation_ = 0.0; // m_0 (no field, kept for magnetisation())
  HarmonicChoice choice_;
  bool consecutive_ = false; // orders are 1, 2, ..., N: powers by recurrence
  void build_responses();
  void radial_factors_at(double r, std::vector<double> &fr, std::vector<double> &ft) const;
};

} // namespace magbrush
