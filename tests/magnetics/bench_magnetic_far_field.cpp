// The cell-multipole far field against the hard cutoff: force error against cost on brushes
// (chains of 60 µm beads along 130 mT, μr 3.9), and the cost at the nip's size.
//
//  1. open brush (nothing periodic): reference = an independent brute-force mutual-dipole
//     solve over ALL pairs (no list, no cutoff), Jacobi to 1e-11;
//  2. z-periodic strip (the nip slab's topology): reference = the far field at order 5,
//     which the verification test checks against direct image sums;
//  3. x/z-periodic brush (the compression box): the same, order 5 reference;
//  4. cost per evaluation at 12,300 beads (the nip case) for the defaults and the cutoffs.
// Errors: RMS over beads |F − F_ref| / RMS |F_ref|, and the total force on the beads touching
// the plane (the brush's push on the stage/plate). Prints tables; asserts nothing.
//
//   bench_magnetic_far_field [chains_small] [chains_large] [cost]   (cost: only table 4)
#include "tests/magnetics/brush_configuration.h"
#include "magnetics/dipole_physics.h"
#include "magnetics/induced_dipoles.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <vector>

using namespace magbrush::magnetics;
using bench::BrushConfiguration;

namespace {

constexpr double B_applied = 0.13;

double cpu_seconds()
{
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

struct Forces
{
  std::vector<double> f; // 3 per bead
};

BeadArrays arrays(const BrushConfiguration &c)
{
  return {c.size(), c.x.data(), c.y.data(), c.z.data(), c.radius.data(), c.mu_r.data(), nullptr};
}

// Brute-force mutual dipoles over all pairs of an open cloud.
Forces brute_force(const BrushConfiguration &c)
{
  const std::size_t n = c.size();
  std::vector<double> p(3 * n), q(3 * n), alpha(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    alpha[k] = polarisability(c.radius[k], clausius_mossotti(c.mu_r[k]));
    p[3 * k + 1] = alpha[k] * B_applied;
  }
  for (int sweep = 0; sweep < 200; ++sweep)
  {
    double change = 0.0, size = 0.0;
#pragma omp parallel for schedule(dynamic, 16) reduction(max : change, size)
    for (long i = 0; i < static_cast<long>(n); ++i)
    {
      double B[3] = {0.0, B_applied, 0.0};
      for (std::size_t k = 0; k < n; ++k)
        if (static_cast<long>(k) != i)
        {
          const double r[3] = {c.x[i] - c.x[k], c.y[i] - c.y[k], c.z[i] - c.z[k]};
          DipoleTensor::at(r).add_field(&p[3 * k], B);
        }
      for (int d = 0; d < 3; ++d)
      {
        q[3 * i + d] = alpha[i] * B[d];
        change = std::max(change, std::abs(q[3 * i + d] - p[3 * i + d]));
        size = std::max(size, std::abs(q[3 * i + d]));
      }
    }
    p.swap(q);
    if (change <= 1e-11 * size)
      break;
  }
  Forces out;
  out.f.assign(3 * n, 0.0);
#pragma omp parallel for schedule(dynamic, 16)
  for (long i = 0; i < static_cast<long>(n); ++i)
    for (std::size_t k = 0; k < n; ++k)
      if (static_cast<long>(k) != i)
      {
        const double r[3] = {c.x[i] - c.x[k], c.y[i] - c.y[k], c.z[i] - c.z[k]};
        double F[3];
        dipole_pair_force(r, &p[3 * i], &p[3 * k], F);
        for (int d = 0; d < 3; ++d)
          out.f[3 * i + d] += F[d];
      }
  return out;
}

struct Run
{
  Forces forces;
  MagneticStats stats;
  double cpu = 0.0, wall = 0.0;
};

// One evaluation as in a DEM refresh: the solver first evaluates the configuration with
// every bead displaced by 5 % of its radius (the staleness limit) in a random direction, then
// — warm — the configuration itself, which is timed and compared.
Run run(const BrushConfiguration &c, const std::array<double, 3> &box, MagneticSettings s)
{
  s.tolerance = 1e-8;
  InducedDipoles solver(s, box);
  const std::size_t n = c.size();
  BrushConfiguration moved = c;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  for (std::size_t k = 0; k < n; ++k)
  {
    double d[3] = {g(rng), g(rng), g(rng)};
    const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    moved.x[k] += 0.05 * c.radius[k] * d[0] / norm;
    moved.y[k] += 0.05 * c.radius[k] * d[1] / norm;
    moved.z[k] += 0.05 * c.radius[k] * d[2] / norm;
  }
  Run r;
  r.forces.f.assign(3 * n, 0.0);
  std::vector<double> fx(n), fy(n), fz(n);
  solver.compute(arrays(moved), uniform_field(0, B_applied, 0), 0.0, {fx.data(), fy.data(), fz.data()});
  std::fill(fx.begin(), fx.end(), 0.0);
  std::fill(fy.begin(), fy.end(), 0.0);
  std::fill(fz.begin(), fz.end(), 0.0);
  const double t0 = cpu_seconds(), w0 = omp_get_wtime();
  r.stats = solver.compute(arrays(c), uniform_field(0, B_applied, 0), 0.0, {fx.data(), fy.data(), fz.data()});
  r.cpu = cpu_seconds() - t0;
  r.wall = omp_get_wtime() - w0;
  for (std::size_t k = 0; k < n; ++k)
  {
    r.forces.f[3 * k] = fx[k];
    r.forces.f[3 * k + 1] = fy[k];
    r.forces.f[3 * k + 2] = fz[k];
  }
  return r;
}

void errors(const BrushConfiguration &c, const Forces &f, const Forces &ref, double &rms,
            double &plane)
{
  double e = 0.0, s = 0.0, fp = 0.0, fr = 0.0;
  for (std::size_t k = 0; k < f.f.size(); ++k)
  {
    e += (f.f[k] - ref.f[k]) * (f.f[k] - ref.f[k]);
    s += ref.f[k] * ref.f[k];
  }
  for (std::size_t b : c.on_plane)
  {
    fp += f.f[3 * b + 1];
    fr += ref.f[3 * b + 1];
  }
  rms = std::sqrt(e / s);
  plane = std::abs(fp - fr) / std::abs(fr);
}

// The scene this bench was written for: a hard cutoff at 8 diameters (no far field),
// tolerance 1e-6, a full refresh when a bead moved too far. MagneticSettings{} is what a
// default case runs (the cell-multipole far field, 12 d, 1e-4, relative staleness), so the
// bench starts from these and sets what each table varies.
MagneticSettings hard_cutoff_settings()
{
  MagneticSettings s;
  s.cutoff_diameters = 8.0;
  s.tolerance = 1e-6;
  s.far_field = FarField::none;
  s.staleness_mode = StalenessMode::absolute;
  return s;
}

MagneticSettings far(int order, double cell, int reach, int passes, DipoleModel model)
{
  MagneticSettings s = hard_cutoff_settings();
  s.model = model;
  s.far_field = FarField::cell_multipole;
  s.far_order = order;
  s.far_cell_diameters = cell;
  s.far_near_reach = reach;
  s.far_passes = passes;
  return s;
}

MagneticSettings cutoff(double diameters, DipoleModel model, bool tail)
{
  MagneticSettings s = hard_cutoff_settings();
  s.model = model;
  s.cutoff_diameters = diameters;
  s.slab_tail_correction = tail;
  return s;
}

void table(const char *title, const BrushConfiguration &c, const std::array<double, 3> &box,
           const Forces &ref, DipoleModel model, bool tail)
{
  std::printf("\n%s: %zu beads\n\n", title, c.size());
  std::printf("| method | near pairs | M2L | sweeps | far passes | CPU/eval [s] | RMS err | plane-force err |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  auto row = [&](const char *name, const MagneticSettings &s) {
    const Run r = run(c, box, s);
    double rms, plane;
    errors(c, r.forces, ref, rms, plane);
    std::printf("| %s | %zu | %zu | %d | %d | %.3f | %.1e | %.1e |\n", name, r.stats.pairs,
                r.stats.far_interactions, r.stats.sweeps, r.stats.far_passes, r.cpu, rms, plane);
  };
  for (double d : {4.0, 8.0, 12.0})
  {
    char name[64];
    std::snprintf(name, sizeof name, "cutoff %.0f d%s", d, tail ? " + slab tail" : "");
    row(name, cutoff(d, model, tail));
  }
  struct Far { int reach; double cell; int order, passes; };
  for (const Far &f : {Far{1, 2.0, 2, 1}, Far{1, 2.0, 3, 1}, Far{2, 1.0, 2, 1}, Far{2, 1.5, 1, 1},
                       Far{2, 1.5, 2, 1}, Far{2, 1.5, 3, 1}, Far{2, 2.0, 2, 1}, Far{2, 1.5, 2, 2}})
  {
    char name[96];
    std::snprintf(name, sizeof name, "far: reach %d, cell %.1f d, order %d, %d pass%s", f.reach,
                  f.cell, f.order, f.passes, f.passes > 1 ? "es" : "");
    row(name, far(f.order, f.cell, f.reach, f.passes, model));
  }
  // The models at the default far field (against this table's reference).
  for (DipoleModel m : {DipoleModel::point_dipole, DipoleModel::mutual_dipole, DipoleModel::corrected})
  {
    char name[96];
    std::snprintf(name, sizeof name, "far default, model %s", to_string(m).c_str());
    row(name, far(2, 1.5, 2, 1, m));
  }
}

} // namespace

int main(int argc, char **argv)
{
  const std::size_t chains = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 100;
  const std::size_t chains_large = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 1100;
  const bool cost_only = argc > 3 && std::string(argv[3]) == "cost";
  std::printf("bench_magnetic_far_field: %d OpenMP threads\n", omp_get_max_threads());

  // 1. Open brush, brute-force reference (mutual_dipole: the brute force has no correction).
  if (!cost_only)
  {
    const BrushConfiguration c = bench::make_brush(chains, 0.9e-3, 30e-6, 3e-6, 8, 16, 3.9, 7);
    const Forces ref = brute_force(c);
    table("Open brush (nothing periodic), mutual_dipole, reference: brute force over all pairs",
          c, {0, 0, 0}, ref, DipoleModel::mutual_dipole, false);
  }
  // 2. z-periodic strip, corrected, reference: far field order 5.
  if (!cost_only)
  {
    const BrushConfiguration c = bench::make_brush(chains, 0.9e-3, 30e-6, 3e-6, 8, 16, 3.9, 7, false);
    const std::array<double, 3> box = {0.0, 0.0, c.box};
    const Forces ref = run(c, box, far(5, 1.5, 2, 4, DipoleModel::corrected)).forces;
    table("Strip periodic along z (nip topology), corrected, reference: far field order 5",
          c, box, ref, DipoleModel::corrected, false);
  }
  // 3. x/z-periodic brush (compression box), corrected, reference: far field order 5.
  if (!cost_only)
  {
    const BrushConfiguration c = bench::make_brush(chains, 0.9e-3, 30e-6, 3e-6, 8, 16, 3.9, 7);
    const std::array<double, 3> box = {c.box, 0.0, c.box};
    const Forces ref = run(c, box, far(5, 1.5, 2, 4, DipoleModel::corrected)).forces;
    table("Brush periodic along x and z (compression box), corrected, reference: far field order 5",
          c, box, ref, DipoleModel::corrected, true);
  }
  // 4. Cost at the nip's size: a z-periodic strip (1 mm period, 6.5 mm wide) of ~12,000
  //    beads, warm start as in a refresh.
  {
    const BrushConfiguration c =
      bench::make_brush(chains_large, 1e-3, 30e-6, 3e-6, 8, 14, 3.9, 9, false, 6.5e-3);
    const std::array<double, 3> box = {0.0, 0.0, c.box};
    std::printf("\nCost at the nip's size: z-periodic strip 6.5 mm x 1 mm, %zu beads, corrected, warm start\n\n", c.size());
    std::printf("| method | near pairs | M2L | sweeps | far passes | wall/eval [s] | lists | tensors | far | sweeps | forces |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    auto row = [&](const char *name, const MagneticSettings &s) {
      const Run r = run(c, box, s);
      const MagneticStats &st = r.stats;
      std::printf("| %s | %zu | %zu | %d | %d | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n", name,
                  st.pairs, st.far_interactions, st.sweeps, st.far_passes, r.wall, st.time_lists,
                  st.time_tensors, st.time_far, st.time_sweeps, st.time_forces);
    };
    row("cutoff 12 d", cutoff(12.0, DipoleModel::corrected, false));
    row("cutoff 4 d", cutoff(4.0, DipoleModel::corrected, false));
    struct Far { int reach; double cell; int order; };
    for (const Far &f : {Far{1, 2.0, 2}, Far{2, 1.0, 2}, Far{2, 1.5, 1}, Far{2, 1.5, 2}, Far{2, 1.5, 3}})
    {
      char name[96];
      std::snprintf(name, sizeof name, "far: reach %d, cell %.1f d, order %d", f.reach, f.cell, f.order);
      row(name, far(f.order, f.cell, f.reach, 1, DipoleModel::corrected));
    }
    MagneticSettings dbl = far(2, 1.5, 2, 1, DipoleModel::corrected);
    dbl.far_single_precision = false;
    row("far: reach 2, cell 1.5 d, order 2, M2L in double", dbl);
    MagneticSettings pd = far(2, 1.5, 2, 1, DipoleModel::point_dipole);
    row("far: reach 2, cell 1.5 d, order 2, point_dipole", pd);
    MagneticSettings md = far(2, 1.5, 2, 1, DipoleModel::mutual_dipole);
    row("far: reach 2, cell 1.5 d, order 2, mutual_dipole", md);
  }
  return 0;
}
