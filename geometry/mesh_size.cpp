// Analytic mesh size function (see mesh_size.h).
#include "geometry/mesh_size.h"

#include "geometry/wall_primitives.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush {

MeshSizeFunction::MeshSizeFunction(double far_size, double grading)
  : far_size_(far_size), grading_(grading)
{
  if (!(far_size > 0.0) || !(grading > 0.0))
    throw std::invalid_argument("mesh size: the far size and the grading must be positive, found " +
                                std::to_string(far_size) + " m and " + std::to_string(grading));
}

void MeshSizeFunction::add_annulus(const Vec2 &c, double r_lo, double r_hi, double size)
{
  features_.push_back({[c, r_lo, r_hi](const Vec2 &x) {
                         const double r = std::hypot(x[0] - c[0], x[1] - c[1]);
                         return std::max({0.0, r_lo - r, r - r_hi});
                       },
                       size});
}

void MeshSizeFunction::add_resolved_circle(const Vec2 &c, double radius, int segments)
{
  add_annulus(c, radius, radius, 2.0 * M_PI * radius / segments);
}

void MeshSizeFunction::add_disk(const Vec2 &p, double radius, double size)
{
  features_.push_back(
      {[p, radius](const Vec2 &x) { return std::max(0.0, std::hypot(x[0] - p[0], x[1] - p[1]) - radius); },
       size});
}

void MeshSizeFunction::add_polygon(const std::vector<Vec2> &polygon, double size)
{
  features_.push_back({[polygon](const Vec2 &x) {
                         return point_in_polygon(x, polygon) ? 0.0 : distance_to_polygon_boundary(x, polygon);
                       },
                       size});
}

double MeshSizeFunction::operator()(const Vec2 &x) const
{
  double h = far_size_;
  for (const auto &f : features_)
    h = std::min(h, f.size + grading_ * f.distance(x));
  return h;
}

Progression graded_division(double length, double h0, double h1)
{
  if (!(length > 0.0) || !(h0 > 0.0) || !(h1 > 0.0))
    throw std::invalid_argument("graded_division: length and sizes must be positive");
  if (length <= std::min(h0, h1))
    return {1, 1.0};
  if (std::abs(h1 - h0) <= 0.05 * h0 || length <= std::max(h0, h1))
  {
    // (Nearly) uniform, or too short to reach h1: the mean size decides.
    return {std::max(1, static_cast<int>(std::ceil(length / (0.5 * (h0 + h1))))), 1.0};
  }
  // Sizes h0 r^k, k = 0..n−1, with h0 r^(n−1) = h1 and Σ = length:
  //   r = (length − h0) / (length − h1),   n = 1 + ln(h1/h0) / ln r.
  const double r = (length - h0) / (length - h1);
  const int n = std::max(1, static_cast<int>(std::lround(1.0 + std::log(h1 / h0) / std::log(r))));
  return {n, n > 1 ? std::pow(h1 / h0, 1.0 / (n - 1)) : 1.0};
}

} // namespace magbrush
