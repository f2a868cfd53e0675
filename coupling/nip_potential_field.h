// The nip's electric field at a charged particle, at any moment of the latent image's travel
// with the drum: E = −∇Φ with
//
//     Φ(x, y, t) = Φ_bias(x, y) + Φ_image(x, y; u(t)),
//
// from the stored electric grid (field_grid.h NipPotentialGrid: the bias solution and the image
// solution at K phases u_k = k P / K over one image period P). This is what the DEM's qE term
// (dem/force_terms/electric_field_force.h) calls per charged particle per step; no deal.II.
//
// The phase. The image is fixed to the drum surface. At t ≤ 0 (and while the particles settle)
// it is where the case puts it: the surface value at arc length s from the nip point
// (counter-clockwise about the drum centre) is latent_image_value(image, s), an exposed strip
// centred on the nip (field_solver/nip_electrostatics.h). The drum turns by
// Θ(t) = ∫₀ᵗ ω(t') dt' (counter-clockwise positive, ω ramped linearly over drum.spin_up_time as
// the drum wall is), so at time t the surface value at s is latent_image_value(image, s − u)
// with u(t) = R_drum Θ(t): surface_travel().
//
// Between the stored phases Φ_image is interpolated in u, either
//  * linearly between the two neighbouring samples (2 patches per lookup), or
//  * trigonometrically (the band-limited interpolant through all K samples, exact for the
//    image harmonics below K/2; K patches per lookup).
// Both reproduce the samples exactly; which is cheaper for a given accuracy is measured by
// tests/coupling/field_grid/bench_nip_potential_field.cpp (docs/electrostatics.md). The
// weights depend on the time only: phase_weights() fills them once per step, evaluate() uses
// them for every particle.
//
// In space, each sample is the tensor-product cubic spline of field_grid.h (E C1 across cells,
// O(h³)). Outside the window E = 0 and evaluate() returns false (the caller counts these
// lookups): the window covers the development zone around the nip; see docs/electrostatics.md
// for why zero is the stated value there and what it neglects.
//
// Cost: (weights + 1) × 16 multiply-adds to combine the patch corners, one Hermite patch; no
// allocation, no virtual call; safe to call from many threads at once.
#pragma once

#include "coupling/case_model.h"
#include "coupling/field_grid.h"

#include <string>
#include <vector>

namespace magbrush {

class NipPotentialField
{
public:
  enum class PhaseInterpolation { linear, trigonometric };

  // The weights of the phase samples at one moment: weight[m] on sample index[m], m < count.
  struct PhaseWeights
  {
    int count = 0;
    std::vector<int> index;
    std::vector<double> weight;
  };

  explicit NipPotentialField(const NipPotentialGrid &grid,
                             PhaseInterpolation interpolation = PhaseInterpolation::linear);

  // What `magbrush dem` does: read the electric grid at `grid_path`
  // (coupling/field_files.h electric_grid_path), check that it was computed for this case
  // (throws ProvenanceMismatch naming the key otherwise) and interpolate it. FieldGridError
  // when the file is missing or malformed.
  static NipPotentialField for_case(const Case &c, const std::string &grid_path,
                                    PhaseInterpolation interpolation = PhaseInterpolation::linear);

  // u(t) = R Θ(t) [m]: the arc length the drum surface has travelled since t = 0 (0 for t ≤ 0).
  static double surface_travel(const Drum &drum, double t);

  // Buffers sized for this field (call once, outside the step loop).
  PhaseWeights make_phase_weights() const;
  // The weights at image travel u [m] (no allocation).
  void phase_weights(double u, PhaseWeights &w) const;

  // E [V/m] at x [m] (z ignored, E_z = 0) with the given weights: true inside the window
  // (edges included); false and E = 0 outside.
  bool evaluate(const Vec3 &x, const PhaseWeights &w, Vec3 &E) const
  {
    double out[6];
    if (!patch(x, w, out))
    {
      E = {0.0, 0.0, 0.0};
      return false;
    }
    E = {-out[1] / dx_, -out[2] / dy_, 0.0};
    return true;
  }
  // Φ [V] inside the window, NaN outside.
  double potential(const Vec3 &x, const PhaseWeights &w) const;
  bool contains(const Vec3 &x) const
  {
    return x[0] >= x_min_ && x[0] <= x_max_ && x[1] >= y_min_ && x[1] <= y_max_;
  }

  int phase_samples() const { return K_; }
  double image_period() const { return period_; }
  PhaseInterpolation interpolation() const { return interpolation_; }
  const char *interpolation_name() const;
  double x_min() const { return x_min_; }
  double x_max() const { return x_max_; }
  double y_min() const { return y_min_; }
  double y_max() const { return y_max_; }
  size_t memory_bytes() const { return (bias_.size() + image_.size()) * sizeof(double); }

private:
  bool patch(const Vec3 &x, const PhaseWeights &w, double out[6]) const
  {
    if (!contains(x))
      return false;
    const double s = (x[0] - x_min_) / dx_, t = (x[1] - y_min_) / dy_;
    int i = static_cast<int>(s), j = static_cast<int>(t);
    i = i > n_x_ - 2 ? n_x_ - 2 : i;
    j = j > n_y_ - 2 ? n_y_ - 2 : j;
    // The four corners' Hermite data [f, f_p, f_q, f_pq] of Φ_bias + Σ w_m Φ_image,k_m.
    double c[4][4];
    const size_t node[4] = {static_cast<size_t>(i) * n_y_ + j, static_cast<size_t>(i) * n_y_ + j + 1,
                            static_cast<size_t>(i + 1) * n_y_ + j,
                            static_cast<size_t>(i + 1) * n_y_ + j + 1};
    for (int a = 0; a < 4; ++a)
    {
      const double *b = &bias_[node[a] * 4];
      c[a][0] = b[0];
      c[a][1] = b[1];
      c[a][2] = b[2];
      c[a][3] = b[3];
      const double *img = &image_[node[a] * static_cast<size_t>(K_) * 4];
      for (int m = 0; m < w.count; ++m)
      {
        const double *d = img + 4 * w.index[m];
        const double wm = w.weight[m];
        c[a][0] += wm * d[0];
        c[a][1] += wm * d[1];
        c[a][2] += wm * d[2];
        c[a][3] += wm * d[3];
      }
    }
    spline::evaluate_patch(c[0], c[1], c[2], c[3], s - i, t - j, out);
    return true;
  }

  double x_min_, x_max_, y_min_, y_max_, dx_, dy_;
  int n_x_, n_y_, K_;
  double period_;
  PhaseInterpolation interpolation_;
  std::vector<double> bias_;  // [f, f_p, f_q, f_pq] per node (field_grid.h)
  std::vector<double> image_; // per node, per sample k: [f, f_p, f_q, f_pq] (node-major)
};

} // namespace magbrush
