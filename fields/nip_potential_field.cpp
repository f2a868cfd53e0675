// The nip potential at any phase of the latent image: construction, phase weights, the drum's
// surface travel (see nip_potential_field.h).
#include "fields/nip_potential_field.h"

#include "case/case_hash.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace magbrush {

namespace {
constexpr double pi = 3.14159265358979323846;
}

NipPotentialField::NipPotentialField(const NipPotentialGrid &grid, PhaseInterpolation interpolation)
  : x_min_(grid.bias.x_min), x_max_(grid.bias.x_max), y_min_(grid.bias.y_min),
    y_max_(grid.bias.y_max), dx_(0.0), dy_(0.0), n_x_(grid.bias.n_x), n_y_(grid.bias.n_y),
    K_(grid.phase_samples()), period_(grid.image_period), cx_(grid.drum_center[0]),
    cy_(grid.drum_center[1]), drum_radius_(grid.drum_radius), interpolation_(interpolation)
{
  validate(grid, "NipPotentialField");
  if (interpolation_ == PhaseInterpolation::co_moving && period_ > 0.0 && !(drum_radius_ > 0.0))
    throw FieldGridError("NipPotentialField: co-moving phase interpolation needs the drum's "
                         "centre and radius in the grid (drum_radius > 0)");
  dx_ = grid.bias.dx();
  dy_ = grid.bias.dy();
  bias_ = spline::bicubic_hermite_data(grid.bias.phi, n_x_, n_y_, /*periodic*/ false);
  // Interleave the samples per node, so that one lookup reads one contiguous block per corner.
  const size_t n = grid.bias.phi.size();
  image_.assign(n * static_cast<size_t>(K_) * 4, 0.0);
  for (int k = 0; k < K_; ++k)
  {
    const std::vector<double> data =
      spline::bicubic_hermite_data(grid.image[static_cast<size_t>(k)], n_x_, n_y_, false);
    for (size_t node = 0; node < n; ++node)
      for (int c = 0; c < 4; ++c)
        image_[(node * static_cast<size_t>(K_) + static_cast<size_t>(k)) * 4 + c] = data[node * 4 + c];
  }
}

NipPotentialField NipPotentialField::for_case(const Case &c, const std::string &grid_path,
                                              PhaseInterpolation interpolation)
{
  const ElectricGridFile file = read_electric_grid(grid_path);
  check_provenance(file.info, field_inputs(c, FieldKind::electric));
  return NipPotentialField(file.grid, interpolation);
}

double NipPotentialField::surface_travel(const Drum &drum, double t)
{
  // Θ(t) = ∫ ω, the spin-up ramp included (Drum::turned).
  return drum.radius * drum.turned(t);
}

NipPotentialField::PhaseWeights NipPotentialField::make_phase_weights() const
{
  PhaseWeights w;
  const size_t n = static_cast<size_t>(K_ < 2 ? 2 : K_); // co-moving uses two with K = 1
  w.index.assign(n, 0);
  w.weight.assign(n, 0.0);
  w.turn_cos.assign(n, 1.0);
  w.turn_sin.assign(n, 0.0);
  return w;
}

void NipPotentialField::phase_weights(double u, PhaseWeights &w) const
{
  const size_t n = static_cast<size_t>(K_ < 2 ? 2 : K_);
  if (w.index.size() < n || w.weight.size() < n || w.turn_cos.size() < n || w.turn_sin.size() < n)
    throw std::invalid_argument("NipPotentialField::phase_weights: buffers for " +
                                std::to_string(w.index.size()) + " samples, the field has " +
                                std::to_string(K_) + " (use make_phase_weights)");
  w.turn_cos[0] = w.turn_cos[1] = 1.0;
  w.turn_sin[0] = w.turn_sin[1] = 0.0;
  if (period_ <= 0.0)
  {
    w.count = 1;
    w.index[0] = 0;
    w.weight[0] = 1.0;
    return;
  }
  // The phase in units of the sample spacing, in [0, K).
  double f = u / period_;
  f = (f - std::floor(f)) * K_;
  if (f >= K_)
    f = 0.0;
  int k0 = static_cast<int>(f);
  double frac = f - k0;
  // Within round-off of a sample (1e-9 of the sample spacing): that sample alone, so that the
  // stored phases are reproduced exactly.
  if ((frac < 1e-9 || frac > 1.0 - 1e-9) && interpolation_ != PhaseInterpolation::co_moving)
  {
    w.count = 1;
    w.index[0] = frac < 0.5 ? k0 : (k0 + 1) % K_;
    w.weight[0] = 1.0;
    return;
  }
  if (interpolation_ == PhaseInterpolation::co_moving)
  {
    // Samples k0 and k0 + 1 (one sample, K = 1, serves both sides), each turned by its
    // distance from u along the surface: (u − u_k)/R with u − u_k0 = frac P/K ≥ 0 and
    // u − u_k0+1 = (frac − 1) P/K ≤ 0.
    const double spacing = period_ / K_;
    const double alpha[2] = {frac * spacing / drum_radius_, (frac - 1.0) * spacing / drum_radius_};
    w.count = 2;
    w.index[0] = k0;
    w.index[1] = (k0 + 1) % K_;
    w.weight[0] = 1.0 - frac;
    w.weight[1] = frac;
    for (int m = 0; m < 2; ++m)
    {
      w.turn_cos[m] = std::cos(alpha[m]);
      w.turn_sin[m] = std::sin(alpha[m]);
    }
    return;
  }
  if (interpolation_ == PhaseInterpolation::linear)
  {
    w.count = 2;
    w.index[0] = k0;
    w.weight[0] = 1.0 - frac;
    w.index[1] = (k0 + 1) % K_;
    w.weight[1] = frac;
    return;
  }
  // Trigonometric: the periodic interpolant through K equispaced samples, as weights
  // w_k(Δ) = (1/K) [1 + 2 Σ_{m<K/2} cos mΔ (+ cos (K/2)Δ for even K)], Δ = 2π (f − k)/K:
  // sin(KΔ/2) / (K sin(Δ/2)) for odd K, sin(KΔ/2) cot(Δ/2) / K for even K (the Nyquist
  // harmonic as a cosine, so the weights are real and sum to one).
  // sin(KΔ/2) = sin(π (f − k)) = (−1)^k sin(π f).
  const double s_f = std::sin(pi * f);
  for (int k = 0; k < K_; ++k)
  {
    const double half = pi * (f - k) / K_;
    const double sign = (k % 2 == 0) ? 1.0 : -1.0;
    const double ratio = sign * s_f / (K_ * std::sin(half));
    w.index[static_cast<size_t>(k)] = k;
    w.weight[static_cast<size_t>(k)] = K_ % 2 == 0 ? ratio * std::cos(half) : ratio;
  }
  w.count = K_;
}

double NipPotentialField::potential(const Vec3 &x, const PhaseWeights &w) const
{
  double phi, gx, gy;
  return gradient(x, w, phi, gx, gy) ? phi : std::numeric_limits<double>::quiet_NaN();
}

const char *NipPotentialField::interpolation_name() const
{
  switch (interpolation_)
  {
  case PhaseInterpolation::linear:
    return "linear";
  case PhaseInterpolation::trigonometric:
    return "trigonometric";
  case PhaseInterpolation::co_moving:
    return "co-moving";
  }
  return "?";
}

} // namespace magbrush
