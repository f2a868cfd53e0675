// E = −∇Φ from the spline of Φ on the Cartesian nip window.
#include "fields/cartesian_field_interpolator.h"

#include <cmath>
#include <limits>

namespace magbrush {

CartesianFieldInterpolator::CartesianFieldInterpolator(const CartesianGrid &grid)
  : x_min_(grid.x_min), x_max_(grid.x_max), y_min_(grid.y_min), y_max_(grid.y_max), dx_(0),
    dy_(0), n_x_(grid.n_x), n_y_(grid.n_y)
{
  validate(grid, "CartesianFieldInterpolator");
  dx_ = grid.dx();
  dy_ = grid.dy();
  nodes_ = spline::bicubic_hermite_data(grid.phi, n_x_, n_y_, /*periodic*/ false);
}

double CartesianFieldInterpolator::potential(const Vec3 &x) const
{
  double out[6];
  return patch(x, out) ? out[0] : std::numeric_limits<double>::quiet_NaN();
}

} // namespace magbrush
