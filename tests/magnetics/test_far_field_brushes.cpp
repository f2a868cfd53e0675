// The default far field (cell multipoles: order 2, cells of 1.5 mean diameters, near reach 2,
// one far-field pass per evaluation) on brushes, against references that share no code with
// it: mutual dipoles solved by brute force over every pair, and for the periodic strip over
// every pair and ±100 periodic images (the line sums of 1/r³ beyond them change the forces by
// ~1e-5). The brushes are those of bench_magnetic_far_field (chains of 60 µm beads, ±10 %,
// μr 3.9, along 130 mT), evaluated warm as in a DEM refresh.
//
// Errors: RMS over beads |F − F_ref| / RMS |F_ref|; plane = |ΣF_y − ΣF_y,ref| / |ΣF_y,ref| over
// the beads touching the plane y = 0 (the brush's push on the stage). Measured: open brush
// 6.0e-3 / 1.1e-3, z-periodic strip 1.06e-2 / 4.1e-3 (the strip's figure against the order-5
// far field, which the benchmark uses as its reference, is smaller: that reference is itself
// 2.3e-3 off the image sum). Asserted with about 10 % headroom.
#include "tests/magnetics/brush_configuration.h"

#include "magnetics/dipole_physics.h"
#include "magnetics/induced_dipoles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace magbrush::magnetics;
using bench::BrushConfiguration;

namespace {

constexpr double B_applied = 0.13;

// Mutual dipoles by Jacobi iteration to 1e-12 with the field of every other bead and of every
// periodic image along z up to ±images periods (images = 0: an open cloud), then the forces
// by the same pair sums. The summed pair tensors are built once (they are symmetric in the
// pair), so the iteration costs n² per sweep.
std::vector<double> brute_force(const BrushConfiguration &c, double period_z, int images)
{
  const std::size_t n = c.size();
  std::vector<DipoleTensor> T(n * n, DipoleTensor{0, 0, 0, 0, 0, 0});
#pragma omp parallel for schedule(dynamic, 8)
  for (long i = 0; i < static_cast<long>(n); ++i)
    for (std::size_t k = static_cast<std::size_t>(i); k < n; ++k)
    {
      DipoleTensor sum{0, 0, 0, 0, 0, 0};
      for (int m = -images; m <= images; ++m)
      {
        if (k == static_cast<std::size_t>(i) && m == 0)
          continue;
        const double r[3] = {c.x[i] - c.x[k], c.y[i] - c.y[k], c.z[i] - c.z[k] + m * period_z};
        const DipoleTensor t = DipoleTensor::at(r);
        sum.xx += t.xx, sum.yy += t.yy, sum.zz += t.zz, sum.xy += t.xy, sum.xz += t.xz, sum.yz += t.yz;
      }
      T[i * n + k] = sum;
      T[k * n + i] = sum;
    }
  std::vector<double> p(3 * n, 0.0), q(3 * n), alpha(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    alpha[k] = polarisability(c.radius[k], clausius_mossotti(c.mu_r[k]));
    p[3 * k + 1] = alpha[k] * B_applied;
  }
  for (int sweep = 0; sweep < 500; ++sweep)
  {
    double change = 0.0, size = 0.0;
#pragma omp parallel for schedule(dynamic, 16) reduction(max : change, size)
    for (long i = 0; i < static_cast<long>(n); ++i)
    {
      double B[3] = {0.0, B_applied, 0.0};
      for (std::size_t k = 0; k < n; ++k)
        T[i * n + k].add_field(&p[3 * k], B);
      for (int d = 0; d < 3; ++d)
      {
        q[3 * i + d] = alpha[i] * B[d];
        change = std::max(change, std::abs(q[3 * i + d] - p[3 * i + d]));
        size = std::max(size, std::abs(q[3 * i + d]));
      }
    }
    p.swap(q);
    if (change <= 1e-12 * size)
      break;
  }
  // Forces (a bead's own images pull it equally both ways along z: no net force).
  std::vector<double> f(3 * n, 0.0);
#pragma omp parallel for schedule(dynamic, 8)
  for (long i = 0; i < static_cast<long>(n); ++i)
    for (std::size_t k = 0; k < n; ++k)
    {
      if (k == static_cast<std::size_t>(i))
        continue;
      for (int m = -images; m <= images; ++m)
      {
        const double r[3] = {c.x[i] - c.x[k], c.y[i] - c.y[k], c.z[i] - c.z[k] + m * period_z};
        double F[3];
        dipole_pair_force(r, &p[3 * i], &p[3 * k], F);
        for (int d = 0; d < 3; ++d)
          f[3 * i + d] += F[d];
      }
    }
  return f;
}

// The default far field as a DEM refresh uses it: warm, from the dipoles of the same brush
// with every bead displaced by 5 % of its radius in a random direction (the staleness limit;
// the default single far-field pass per evaluation works from the previous dipoles), the
// Jacobi iteration converged tightly so that what is left is the far field's own error.
std::vector<double> default_far_field(const BrushConfiguration &c, const std::array<double, 3> &box)
{
  MagneticSettings s; // a default case: cell multipoles, order 2, cell 1.5 d, reach 2, 1 pass
  s.model = DipoleModel::mutual_dipole;
  s.tolerance = 1e-10;
  InducedDipoles solver(s, box);
  const std::size_t n = c.size();
  BrushConfiguration moved = c;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  for (std::size_t k = 0; k < n; ++k)
  {
    const double d[3] = {g(rng), g(rng), g(rng)};
    const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    moved.x[k] += 0.05 * c.radius[k] * d[0] / norm;
    moved.y[k] += 0.05 * c.radius[k] * d[1] / norm;
    moved.z[k] += 0.05 * c.radius[k] * d[2] / norm;
  }
  std::vector<double> fx(n, 0.0), fy(n, 0.0), fz(n, 0.0);
  auto beads = [n](const BrushConfiguration &b) {
    return BeadArrays{n, b.x.data(), b.y.data(), b.z.data(), b.radius.data(), b.mu_r.data(), nullptr};
  };
  solver.compute(beads(moved), uniform_field(0, B_applied, 0), 0.0, {fx.data(), fy.data(), fz.data()});
  std::fill(fx.begin(), fx.end(), 0.0);
  std::fill(fy.begin(), fy.end(), 0.0);
  std::fill(fz.begin(), fz.end(), 0.0);
  solver.compute(beads(c), uniform_field(0, B_applied, 0), 0.0, {fx.data(), fy.data(), fz.data()});
  std::vector<double> f(3 * n);
  for (std::size_t k = 0; k < n; ++k)
    f[3 * k] = fx[k], f[3 * k + 1] = fy[k], f[3 * k + 2] = fz[k];
  return f;
}

struct Errors
{
  double rms = 0.0, plane = 0.0;
};

Errors errors(const BrushConfiguration &c, const std::vector<double> &f, const std::vector<double> &ref)
{
  double e = 0.0, s = 0.0, fp = 0.0, fr = 0.0;
  for (std::size_t k = 0; k < f.size(); ++k)
  {
    e += (f[k] - ref[k]) * (f[k] - ref[k]);
    s += ref[k] * ref[k];
  }
  for (std::size_t b : c.on_plane)
  {
    fp += f[3 * b + 1];
    fr += ref[3 * b + 1];
  }
  return {std::sqrt(e / s), std::abs(fp - fr) / std::abs(fr)};
}

} // namespace

TEST(FarFieldOnBrushes, OpenBrushAgainstBruteForce)
{
  const BrushConfiguration c = bench::make_brush(100, 0.9e-3, 30e-6, 3e-6, 8, 16, 3.9, 7);
  const Errors e = errors(c, default_far_field(c, {0, 0, 0}), brute_force(c, 0.0, 0));
  std::printf("open brush, %zu beads: RMS force error %.2e, plane force %.2e\n", c.size(), e.rms, e.plane);
  EXPECT_LT(e.rms, 6.6e-3);
  EXPECT_LT(e.plane, 1.2e-3);
}

TEST(FarFieldOnBrushes, PeriodicStripAgainstDirectImageSum)
{
  const BrushConfiguration c = bench::make_brush(100, 0.9e-3, 30e-6, 3e-6, 8, 16, 3.9, 7, false);
  const Errors e = errors(c, default_far_field(c, {0.0, 0.0, c.box}), brute_force(c, c.box, 100));
  std::printf("z-periodic strip, %zu beads: RMS force error %.2e, plane force %.2e\n", c.size(), e.rms,
              e.plane);
  EXPECT_LT(e.rms, 1.17e-2);
  EXPECT_LT(e.plane, 4.5e-3);
}
