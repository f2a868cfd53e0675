// The nip's electric field at a particle: E = −∇Φ from the potential Φ stored on a Cartesian
// window (field_grid.h). This is what the DEM calls per charged particle per step.
//
// Φ is interpolated by a tensor-product cubic spline (not-a-knot at all four edges), so E is
// C1 across cells; errors Φ O(h⁴), E O(h³) (measured in tests/fields).
// The field is 2D: E_z = 0 and z is ignored.
//
// Outside the window the field is taken as zero: evaluate() returns false and E = 0, and
// potential() returns NaN. The window is chosen by the field solver to cover the nip, where
// the development field acts; elsewhere the particles are far from the drum and the bias
// field is neglected (as in the papers). A particle crossing the window edge sees E jump to
// zero — make the window large enough that the field at its edge is negligible.
//
// Cost: a 4×4 Hermite patch; no allocation, no virtual call.
#pragma once

#include "case/case_model.h"
#include "fields/field_grid.h"

#include <vector>

namespace magbrush {

class CartesianFieldInterpolator
{
public:
  explicit CartesianFieldInterpolator(const CartesianGrid &grid);

  // true and E [V/m] inside the window (edges included); false and E = 0 outside.
  bool evaluate(const Vec3 &x, Vec3 &E) const
  {
    double out[6];
    if (!patch(x, out))
    {
      E = {{0.0, 0.0, 0.0}};
      return false;
    }
    E = {{-out[1] / dx_, -out[2] / dy_, 0.0}};
    return true;
  }
  Vec3 field(const Vec3 &x) const
  {
    Vec3 E;
    evaluate(x, E);
    return E;
  }
  // Φ [V] inside the window, NaN outside.
  double potential(const Vec3 &x) const;
  bool contains(const Vec3 &x) const
  {
    return x[0] >= x_min_ && x[0] <= x_max_ && x[1] >= y_min_ && x[1] <= y_max_;
  }

  double x_min() const { return x_min_; }
  double x_max() const { return x_max_; }
  double y_min() const { return y_min_; }
  double y_max() const { return y_max_; }
  size_t memory_bytes() const { return nodes_.size() * sizeof(double); }

private:
  // Spline value and index-space derivatives {f, f_p, f_q, ...} at x; false outside.
  bool patch(const Vec3 &x, double out[6]) const
  {
    if (!contains(x))
      return false;
    const double s = (x[0] - x_min_) / dx_, t = (x[1] - y_min_) / dy_;
    int i = static_cast<int>(s), j = static_cast<int>(t);
    i = i > n_x_ - 2 ? n_x_ - 2 : i;
    j = j > n_y_ - 2 ? n_y_ - 2 : j;
    const double *row0 = &nodes_[static_cast<size_t>(i) * n_y_ * 4];
    const double *row1 = row0 + static_cast<size_t>(n_y_) * 4;
    spline::evaluate_patch(row0 + 4 * j, row0 + 4 * (j + 1), row1 + 4 * j, row1 + 4 * (j + 1),
                           s - i, t - j, out);
    return true;
  }

  double x_min_, x_max_, y_min_, y_max_, dx_, dy_;
  int n_x_, n_y_;
  std::vector<double> nodes_; // [f, f_p, f_q, f_pq] per node (field_grid.h)
};

} // namespace magbrush
