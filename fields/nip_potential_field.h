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
// Between the stored phases Φ_image is interpolated in u, one of
//  * linear: (1 − f) Φ_k + f Φ_k+1 of the two neighbouring samples at the same point;
//  * trigonometric: the band-limited interpolant through all K samples at the same point
//    (exact for the image harmonics below K/2; K patches per lookup);
//  * co_moving (the default): the two neighbouring samples, each evaluated in the frame that
//    moves with the drum surface — sample k at the point turned back about the drum centre by
//    (u − u_k)/R, its gradient turned forward again — and weighted linearly. A strip edge of
//    the image translates with the surface; the plain interpolants blend two edges at two
//    places (an error of the order of the edge field wherever the edge is nearer than about
//    P/K), the co-moving one moves the edge, and only the slow change of the field with the
//    edge's place relative to the sleeve is interpolated.
// All reproduce the samples exactly; the errors against direct solves at the phase and the
// costs are measured by tests/field_solver/bench_nip_phases.cpp (docs/electrostatics.md). The
// weights depend on the time only: phase_weights() fills them once per step, evaluate() uses
// them for every particle.
//
// In space, each sample is the tensor-product cubic spline of field_grid.h (E C1 across cells,
// O(h³)). Outside the window E = 0 and evaluate() returns false (the caller counts these
// lookups): the window covers the development zone around the nip; see docs/electrostatics.md
// for why zero is the stated value there and what it neglects.
//
// Co-moving lookups whose turned point leaves the window count as outside (E = 0, false): the
// window's usable part is smaller by at most P/K at its edges.
//
// Cost: linear/trigonometric: (weights + 1) × 16 multiply-adds to combine the patch corners
// and one Hermite patch; co_moving: three Hermite patches. No allocation, no virtual call;
// safe to call from many threads at once.
#pragma once

#include "case/case_model.h"
#include "fields/field_grid.h"

#include <string>
#include <vector>

namespace magbrush {

class NipPotentialField
{
public:
  enum class PhaseInterpolation { linear, trigonometric, co_moving };

  // The weights of the phase samples at one moment: weight[m] on sample index[m], m < count;
  // for co_moving also the turn (cos, sin of (u − u_k)/R) that carries sample k to phase u.
  struct PhaseWeights
  {
    int count = 0;
    std::vector<int> index;
    std::vector<double> weight, turn_cos, turn_sin;
  };

  explicit NipPotentialField(const NipPotentialGrid &grid,
                             PhaseInterpolation interpolation = PhaseInterpolation::co_moving);

  // What `magbrush dem` does: read the electric grid at `grid_path`
  // (fields/field_files.h electric_grid_path), check that it was computed for this case
  // (throws ProvenanceMismatch naming the key otherwise) and interpolate it. FieldGridError
  // when the file is missing or malformed.
  static NipPotentialField for_case(const Case &c, const std::string &grid_path,
                                    PhaseInterpolation interpolation = PhaseInterpolation::co_moving);

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
    double phi, gx, gy;
    if (!gradient(x, w, phi, gx, gy))
    {
      E = {{0.0, 0.0, 0.0}};
      return false;
    }
    E = {{-gx, -gy, 0.0}};
    return true;
  }
  // Φ [V] inside the window, NaN outside.
  double potential(const Vec3 &x, const PhaseWeights &w) const;
  bool contains(const Vec3 &x) const { return contains(x[0], x[1]); }
  bool contains(double x, double y) const
  {
    return x >= x_min_ && x <= x_max_ && y >= y_min_ && y <= y_max_;
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
  // The Hermite patch of one node-data array at (x, y): `data` holds 4 doubles per node at a
  // stride of `stride` doubles, starting at `offset`. out = {f, f_p, f_q, ...} (field_grid.h).
  void patch_of(const double *data, size_t stride, size_t offset, double x, double y,
                double out[6]) const
  {
    const double s = (x - x_min_) / dx_, t = (y - y_min_) / dy_;
    int i = static_cast<int>(s), j = static_cast<int>(t);
    i = i > n_x_ - 2 ? n_x_ - 2 : i;
    j = j > n_y_ - 2 ? n_y_ - 2 : j;
    const size_t n00 = static_cast<size_t>(i) * n_y_ + j, n10 = n00 + n_y_;
    spline::evaluate_patch(data + n00 * stride + offset, data + (n00 + 1) * stride + offset,
                           data + n10 * stride + offset, data + (n10 + 1) * stride + offset,
                           s - i, t - j, out);
  }

  // Φ and ∇Φ [V, V/m] at x; false outside the window.
  bool gradient(const Vec3 &x, const PhaseWeights &w, double &phi, double &gx, double &gy) const
  {
    if (!contains(x))
      return false;
    if (interpolation_ != PhaseInterpolation::co_moving)
    {
      // Combine the corners' data of bias and samples, then one patch.
      const double s = (x[0] - x_min_) / dx_, t = (x[1] - y_min_) / dy_;
      int i = static_cast<int>(s), j = static_cast<int>(t);
      i = i > n_x_ - 2 ? n_x_ - 2 : i;
      j = j > n_y_ - 2 ? n_y_ - 2 : j;
      double c[4][4];
      const size_t node[4] = {static_cast<size_t>(i) * n_y_ + j, static_cast<size_t>(i) * n_y_ + j + 1,
                              static_cast<size_t>(i + 1) * n_y_ + j,
                              static_cast<size_t>(i + 1) * n_y_ + j + 1};
      for (int a = 0; a < 4; ++a)
      {
        const double *b = &bias_[node[a] * 4];
        for (int d = 0; d < 4; ++d)
          c[a][d] = b[d];
        const double *img = &image_[node[a] * static_cast<size_t>(K_) * 4];
        for (int m = 0; m < w.count; ++m)
        {
          const double *v = img + 4 * w.index[m];
          const double wm = w.weight[m];
          for (int d = 0; d < 4; ++d)
            c[a][d] += wm * v[d];
        }
      }
      double out[6];
      spline::evaluate_patch(c[0], c[1], c[2], c[3], s - i, t - j, out);
      phi = out[0];
      gx = out[1] / dx_;
      gy = out[2] / dy_;
      return true;
    }
    // Co-moving: sample k at the point turned back by (u − u_k)/R about the drum centre.
    const double rx = x[0] - cx_, ry = x[1] - cy_;
    const size_t stride = static_cast<size_t>(K_) * 4;
    double out[6];
    patch_of(bias_.data(), 4, 0, x[0], x[1], out);
    phi = out[0];
    gx = out[1] / dx_;
    gy = out[2] / dy_;
    for (int m = 0; m < w.count; ++m)
    {
      const double c = w.turn_cos[m], s = w.turn_sin[m];
      const double px = cx_ + c * rx + s * ry, py = cy_ - s * rx + c * ry; // turned by −α
      if (!contains(px, py))
        return false;
      patch_of(image_.data(), stride, 4 * static_cast<size_t>(w.index[m]), px, py, out);
      const double ax = out[1] / dx_, ay = out[2] / dy_;
      const double wm = w.weight[m];
      phi += wm * out[0];
      gx += wm * (c * ax - s * ay); // the gradient turned forward by +α
      gy += wm * (s * ax + c * ay);
    }
    return true;
  }

  double x_min_, x_max_, y_min_, y_max_, dx_, dy_;
  int n_x_, n_y_, K_;
  double period_;
  double cx_, cy_, drum_radius_; // the drum centre and surface radius [m]
  PhaseInterpolation interpolation_;
  std::vector<double> bias_;  // [f, f_p, f_q, f_pq] per node (field_grid.h)
  std::vector<double> image_; // per node, per sample k: [f, f_p, f_q, f_pq] (node-major)
};

} // namespace magbrush
