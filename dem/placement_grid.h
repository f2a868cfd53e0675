// A hash grid of spheres by their centres, for the neighbourhood tests outside the engine's
// step (insertion, the inflow's toner, the carried toner's recapture): which spheres of a
// particle state lie near a point, periodic images included. Cells of a fixed size `cell`
// (at least the largest diameter, so that 3 x 3 x 3 cells hold every touching sphere).
#pragma once

#include "dem/neighbour_list.h"
#include "dem/particle_state.h"

#include <cmath>
#include <unordered_map>
#include <vector>

namespace magbrush::dem {

class PlacementGrid
{
public:
  PlacementGrid(double cell, const PeriodicBox &box) : h_(cell), box_(box) {}

  // Calls f(k, d) for every sphere k of `s` in the grid within the 27 cells around p, with d
  // the separation of its centre from p (nearest periodic image), d[0..2].
  template <typename F>
  void for_each_near(const ParticleState &s, const Vector3 &p, F &&f) const
  {
    const long cx = cell(p.x), cy = cell(p.y), cz = cell(p.z);
    for (long a = -1; a <= 1; ++a)
      for (long b = -1; b <= 1; ++b)
        for (long e = -1; e <= 1; ++e)
        {
          const auto it = cells_.find(key(wrap_cell(cx + a, 0), wrap_cell(cy + b, 1), wrap_cell(cz + e, 2)));
          if (it == cells_.end())
            continue;
          for (std::size_t k : it->second)
          {
            double d[3] = {s.x[k] - p.x, s.y[k] - p.y, s.z[k] - p.z};
            for (int q = 0; q < 3; ++q)
              if (box_.periodic(q))
              {
                const double L = box_.length[static_cast<std::size_t>(q)];
                d[q] -= L * std::round(d[q] / L);
              }
            f(k, d);
          }
        }
  }

  // Whether a sphere (p, r) overlaps a sphere of `s` in the grid.
  bool overlaps(const ParticleState &s, const Vector3 &p, double r) const
  {
    bool hit = false;
    for_each_near(s, p, [&](std::size_t k, const double *d) {
      const double reach = r + s.radius[k];
      hit = hit || d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach;
    });
    return hit;
  }

  void add(const Vector3 &p, std::size_t index)
  {
    cells_[key(wrap_cell(cell(p.x), 0), wrap_cell(cell(p.y), 1), wrap_cell(cell(p.z), 2))].push_back(index);
  }
  void clear() { cells_.clear(); }

private:
  double h_;
  PeriodicBox box_;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
  long cell(double v) const { return static_cast<long>(std::floor(v / h_)); }
  long wrap_cell(long c, int d) const
  {
    if (!box_.periodic(d))
      return c;
    const long n = std::max(1L, static_cast<long>(std::floor(box_.length[static_cast<std::size_t>(d)] / h_)));
    return ((c % n) + n) % n;
  }
  static long long key(long a, long b, long c)
  {
    return (static_cast<long long>(a & 0x1FFFFF) << 42) | (static_cast<long long>(b & 0x1FFFFF) << 21) |
           static_cast<long long>(c & 0x1FFFFF);
  }
};

} // namespace magbrush::dem
