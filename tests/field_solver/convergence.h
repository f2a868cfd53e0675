// Small helpers shared by the field verification tests and benchmarks: error norms over point
// sets and observed convergence orders. No deal.II.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace magbrush::field::testing {

using Vec2 = std::array<double, 2>;

inline std::vector<Vec2> circle_points(double radius, int n, double phase = 0.0)
{
  std::vector<Vec2> p(n);
  for (int k = 0; k < n; ++k)
  {
    const double t = phase + 2.0 * 3.14159265358979323846 * k / n;
    p[k] = {{radius * std::cos(t), radius * std::sin(t)}};
  }
  return p;
}

// max_k |a_k − b_k| / scale
inline double max_vector_error(const std::vector<Vec2> &a, const std::vector<Vec2> &b,
                               double scale)
{
  double e = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    e = std::max(e, std::hypot(a[k][0] - b[k][0], a[k][1] - b[k][1]));
  return e / scale;
}

inline double max_magnitude(const std::vector<Vec2> &a)
{
  double m = 0.0;
  for (const auto &v : a)
    m = std::max(m, std::hypot(v[0], v[1]));
  return m;
}

// Observed order between successive uniform refinements (h halves each level).
inline std::vector<double> observed_orders(const std::vector<double> &errors)
{
  std::vector<double> orders;
  for (std::size_t i = 1; i < errors.size(); ++i)
    orders.push_back(std::log2(errors[i - 1] / errors[i]));
  return orders;
}

inline void print_study(const char *title, const std::vector<double> &errors)
{
  const auto orders = observed_orders(errors);
  std::printf("%s\n  level  rel. max error  order\n", title);
  for (std::size_t i = 0; i < errors.size(); ++i)
    std::printf("  %5zu  %14.3e  %5s\n", i, errors[i],
                i == 0 ? "" : std::to_string(orders[i - 1]).substr(0, 5).c_str());
}

} // namespace magbrush::field::testing
