// A static brush-like configuration for the magnetics benchmarks: chains of touching carrier
// beads standing on a plane (y = 0) along a uniform field B ŷ, in a slab periodic along z and
// (optionally) x, open along y. With x open, the chain roots cover 0 ≤ x < width: a strip,
// like the nip slab that is periodic only along the roller axis. Chains start at random points of the plane,
// lean by a few degrees at every bead, and stop early when they would hit another chain.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace magbrush::magnetics::bench {

struct BrushConfiguration
{
  double box = 0.0;   // periodic length along z [m] (and along x when periodic_x)
  bool periodic_x = true;
  double box_x() const { return periodic_x ? box : 0.0; }
  std::vector<double> x, y, z, radius, mu_r;
  std::vector<std::size_t> on_plane; // beads touching the plane y = 0
  std::size_t size() const { return x.size(); }
};

inline BrushConfiguration make_brush(std::size_t chains, double box, double mean_radius,
                                     double radius_std, int min_height, int max_height,
                                     double mu_r, unsigned seed, bool periodic_x = true,
                                     double width_x = 0.0)
{
  // width_x (open x only): the strip's width; 0 = the periodic length.
  const double width = (!periodic_x && width_x > 0.0) ? width_x : box;
  BrushConfiguration c;
  c.box = box;
  c.periodic_x = periodic_x;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> lateral(0.0, box), across(0.0, width), unit(0.0, 1.0);
  std::normal_distribution<double> radius(mean_radius, radius_std);
  std::uniform_int_distribution<int> height(min_height, max_height);
  auto overlaps = [&](double x, double y, double z, double r) {
    for (std::size_t k = 0; k < c.size(); ++k)
    {
      double dx = x - c.x[k], dy = y - c.y[k], dz = z - c.z[k];
      if (periodic_x)
        dx -= box * std::round(dx / box);
      dz -= box * std::round(dz / box);
      if (dx * dx + dy * dy + dz * dz < (r + c.radius[k]) * (r + c.radius[k]))
        return true;
    }
    return false;
  };
  const double r_lo = 0.8 * mean_radius, r_hi = 1.2 * mean_radius;
  const double gap = 1e-3 * mean_radius; // beads almost touch (D ≈ 2.001)
  for (std::size_t chain = 0, attempts = 0; chain < chains && attempts < 100 * chains; ++attempts)
  {
    double r = std::clamp(radius(rng), r_lo, r_hi);
    double x = across(rng), y = r + gap, z = lateral(rng);
    if (overlaps(x, y, z, r))
      continue;
    ++chain;
    const int n = height(rng);
    for (int k = 0; k < n; ++k)
    {
      c.x.push_back(x);
      c.y.push_back(y);
      c.z.push_back(z);
      c.radius.push_back(r);
      c.mu_r.push_back(mu_r);
      if (k == 0)
        c.on_plane.push_back(c.size() - 1);
      // Next bead: touching, along ŷ tilted by up to 8° in a random azimuth.
      const double r_next = std::clamp(radius(rng), r_lo, r_hi);
      const double tilt = 8.0 * 3.14159265358979 / 180.0 * unit(rng);
      const double azimuth = 2.0 * 3.14159265358979 * unit(rng);
      const double step = r + r_next + gap;
      const double nx = x + step * std::sin(tilt) * std::cos(azimuth);
      const double ny = y + step * std::cos(tilt);
      const double nz = z + step * std::sin(tilt) * std::sin(azimuth);
      if (overlaps(nx, ny, nz, r_next))
        break;
      x = nx;
      y = ny;
      z = nz;
      r = r_next;
    }
  }
  return c;
}

} // namespace magbrush::magnetics::bench
