// Benchmark of the Coulomb far field's accuracy knobs (electrostatics/periodic_coulomb.h):
// the Taylor order and cell size, and the refresh interval, on a nip window with toner — 5,000
// carriers (50 µm, the counter-charge) and 20,000 toner (7 µm, −2 fC ± 50 %) in a slab 2 mm
// along the nip, 0.5 mm across the gap, periodic along z (1 mm), optionally with the pair
// images in the drum (a plane at y = 0, photoconductor εr = 3, 20 µm).
//
// Error: RMS over the charges of |F − F_ref| / RMS |F_ref|, with F_ref the method at order 6,
// cells of 75 µm (50 µm with images) and the M2L in double precision (its own error, measured against the
// Bessel-K row sums on sparse charges: 2e-4 RMS at order 6 with 60 µm cells, relative to a
// far-field-only force; here the near field covers ±0.15 mm and dominates the force). Times are wall seconds on this machine (shared, loaded).
//
// Usage: bench_coulomb [steps_for_refresh_table]
#include "electrostatics/periodic_coulomb.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

using namespace magbrush::electrostatics;

namespace {

struct Scene
{
  std::vector<double> x, y, z, q, r, vx, vy, vz;
  std::size_t size() const { return q.size(); }
};

Scene nip_window(unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene s;
  const double wx = 2e-3, wy = 0.5e-3, wz = 1e-3;
  double total = 0.0;
  auto add = [&](double x, double y, double z, double q, double r) {
    s.x.push_back(x);
    s.y.push_back(y);
    s.z.push_back(z);
    s.q.push_back(q);
    s.r.push_back(r);
    // Relative motion of the brush: ±0.1 m/s.
    s.vx.push_back(0.1 * (2.0 * u(rng) - 1.0));
    s.vy.push_back(0.1 * (2.0 * u(rng) - 1.0));
    s.vz.push_back(0.1 * (2.0 * u(rng) - 1.0));
  };
  // Carriers on a jittered 50 µm-ish lattice (40 × 10 × 12.5 → 5,000), toner at random.
  const int nx = 40, ny = 10, nz = 13;
  int carriers = 0;
  for (int i = 0; i < nx && carriers < 5000; ++i)
    for (int j = 0; j < ny && carriers < 5000; ++j)
      for (int k = 0; k < nz && carriers < 5000; ++k, ++carriers)
        add(wx * (i + 0.5 + 0.2 * (u(rng) - 0.5)) / nx, 30e-6 + (wy - 60e-6) * (j + 0.5 + 0.2 * (u(rng) - 0.5)) / ny,
            wz * (k + 0.5 + 0.2 * (u(rng) - 0.5)) / nz, 0.0, 25e-6);
  for (int t = 0; t < 20000; ++t)
  {
    const double q = -2e-15 * (0.5 + u(rng));
    total += q;
    add(wx * u(rng), 4e-6 + (wy - 8e-6) * u(rng), wz * u(rng), q, 3.5e-6);
  }
  for (int c = 0; c < 5000; ++c)
    s.q[c] = -total / 5000.0;
  return s;
}

double rms_error(const std::vector<double> &E, const std::vector<double> &R, const Scene &s)
{
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (int d = 0; d < 3; ++d)
    {
      num += std::pow(s.q[i] * (E[3 * i + d] - R[3 * i + d]), 2);
      den += std::pow(s.q[i] * R[3 * i + d], 2);
    }
  return std::sqrt(num / den);
}

struct Run
{
  std::vector<double> E;
  double rebuild_s = 0.0, field_s = 0.0;
  PeriodicCoulomb::Times phases;
  std::size_t near = 0;
};

Run evaluate(const Scene &s, int order, double cell, bool single, const GroundedSurface *images, int reach = 2)
{
  CoulombSettings settings;
  settings.near_reach = reach;
  settings.order = order;
  settings.cell_size = cell;
  settings.single_precision = single;
  PeriodicCoulomb c(settings, {0.0, 0.0, 1e-3});
  if (images)
    c.set_image_surface(*images, 2);
  Run run;
  run.E.resize(3 * s.size());
  // The first rebuild of a run is cold (lattice sums, tables); the timed one is the next.
  c.rebuild(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), s.r.data());
  const double t0 = omp_get_wtime();
  c.rebuild(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), s.r.data());
  const double t1 = omp_get_wtime();
  c.field(s.x.data(), s.y.data(), s.z.data(), s.q.data(), s.r.data(), run.E.data(), nullptr);
  const double t2 = omp_get_wtime();
  // A second field() call (the per-step cost between refreshes; the first one warms caches).
  c.field(s.x.data(), s.y.data(), s.z.data(), s.q.data(), s.r.data(), run.E.data(), nullptr);
  run.rebuild_s = t1 - t0;
  run.field_s = omp_get_wtime() - t2;
  run.near = c.near_entries();
  run.phases = c.last_rebuild_times();
  return run;
}

} // namespace

int main(int argc, char **argv)
{
  const int steps = argc > 1 ? std::atoi(argv[1]) : 1000;
  const Scene s = nip_window(1);
  GroundedSurface drum;
  drum.layer = LayeredImages(3.0, 20e-6);
  std::printf("Coulomb far field on a nip window: %zu charges (5,000 carriers + 20,000 toner), slab 2 x 0.5 x 1 mm, "
              "periodic along z; %d threads\n\n",
              s.size(), omp_get_max_threads());
  const GroundedSurface *variants[2] = {nullptr, &drum};
  for (const GroundedSurface *images : variants)
  {
    std::printf("%s\n", images ? "with pair images in the drum (2 explicit + 1 lumped per charge)"
                               : "without images");
    const Run ref = evaluate(s, 6, images ? 50e-6 : 75e-6, false, images);
    std::printf("  reference (order 6, cell %.0f um, double M2L): rebuild %.3f s, near pairs per step %.3f s\n",
                images ? 50.0 : 75.0, ref.rebuild_s, ref.field_s);
    std::printf("  %5s %8s %12s %12s %28s %14s %12s\n", "order", "cell", "RMS error", "rebuild [s]",
                "(cells+pairs, rows, far) [s]", "near/step [s]", "near rows");
    for (double cell : {25e-6, 50e-6})
      for (int order : {2, 4, 6})
      {
        if (images && order == 6)
          continue;
        const Run run = evaluate(s, order, cell, true, images);
        std::printf("  %5d %5.0f um %12.2e %12.3f %8.3f %8.3f %8.3f %14.4f %12zu\n", order, cell * 1e6,
                    rms_error(run.E, ref.E, s), run.rebuild_s, run.phases.cells, run.phases.rows, run.phases.far,
                    run.field_s, run.near);
      }
    std::printf("\n");
  }

  // Refresh interval: the far field held for n steps of 20 ns while the charges move at
  // ±0.1 m/s (2 nm per step); error of the held field at the END of the interval against a
  // fresh evaluation, and the amortised cost per step.
  std::printf("refresh interval (order 4, cell 25 um, no images; 20 ns steps, ±0.1 m/s):\n");
  std::printf("  %8s %10s %14s %16s\n", "steps", "moved", "RMS error", "cost/step [s]");
  const Run base = evaluate(s, 4, 25e-6, true, nullptr);
  for (int n : {1, 10, 100, steps})
  {
    CoulombSettings settings;
    settings.order = 4;
    settings.cell_size = 25e-6;
    PeriodicCoulomb held(settings, {0.0, 0.0, 1e-3});
    held.rebuild(s.size(), s.x.data(), s.y.data(), s.z.data(), s.q.data(), s.r.data());
    Scene moved = s;
    const double dt = 20e-9 * n;
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      moved.x[i] += s.vx[i] * dt;
      moved.y[i] += s.vy[i] * dt;
      moved.z[i] += s.vz[i] * dt;
    }
    std::vector<double> E(3 * s.size());
    held.field(moved.x.data(), moved.y.data(), moved.z.data(), moved.q.data(), moved.r.data(), E.data(), nullptr);
    const Run fresh = evaluate(moved, 4, 25e-6, true, nullptr);
    std::printf("  %8d %7.2f um %14.2e %16.5f\n", n, 0.1 * dt * 1e6, rms_error(E, fresh.E, moved),
                base.rebuild_s / n + base.field_s);
  }

  // The whole Coulomb force held (dem/force_terms/held_forces.h, electric.hold_distance):
  // evaluated (near pairs and far field) once, then held until the fastest charge has moved d.
  // The error at the END of the hold (the largest it gets) against a fresh evaluation, and the
  // evaluations saved at a 0.5 ns step (the toner's Hertz step) when the fastest charge moves
  // at 1 m/s (a toner flying across the gap).
  std::printf("\nheld forces (order 4, cell 25 um, no images; error when the fastest charge has moved d):\n");
  std::printf("  %8s %14s %22s %16s\n", "d [nm]", "RMS error", "steps per evaluation", "cost/step [s]");
  double v_max = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
    v_max = std::max(v_max, std::sqrt(s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]));
  for (double d : {5e-9, 10e-9, 20e-9, 50e-9, 100e-9})
  {
    Scene moved = s;
    const double dt = d / v_max;
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      moved.x[i] += s.vx[i] * dt;
      moved.y[i] += s.vy[i] * dt;
      moved.z[i] += s.vz[i] * dt;
    }
    const Run fresh = evaluate(moved, 4, 25e-6, true, nullptr);
    const double steps_per_evaluation = d / (1.0 * 0.5e-9);
    std::printf("  %8.0f %14.2e %22.0f %16.5f\n", d * 1e9, rms_error(base.E, fresh.E, moved), steps_per_evaluation,
                (base.rebuild_s / 4000.0 + base.field_s) / steps_per_evaluation);
  }
  return 0;
}
