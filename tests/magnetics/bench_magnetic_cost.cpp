// Cost knobs of the DEM magnetics on a static brush (chains of 60 µm beads along a 130 mT
// field in a periodic slab): error against cost for the cutoff, the model and the
// mutual-induction tolerance. Prints tables; asserts nothing.
//
// The reference for the cutoff study is an independent brute-force mutual-dipole solve over
// all beads and periodic images within a large radius (no neighbour list, tensors recomputed
// on the fly). The dipole sums of a slab converge only like 1/R_c (the far field of a
// polarised slab), so the reference itself is checked against a second, smaller radius.
//
//   bench_magnetic_cost [chains] [reference_cutoff_diameters]
#include "tests/magnetics/brush_configuration.h"
#include "magnetics/dipole_physics.h"
#include "magnetics/induced_dipoles.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace magbrush::magnetics;
using bench::BrushConfiguration;

namespace {

constexpr double B_applied = 0.13; // [T], along y

struct Forces
{
  std::vector<double> fx, fy, fz;
};

double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Process CPU time [s]: on a loaded machine, with one thread, a steadier cost measure than
// wall time (it also counts OpenMP spin-waiting when several threads run).
double cpu_seconds()
{
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

BeadArrays arrays(const BrushConfiguration &c)
{
  return {c.size(), c.x.data(), c.y.data(), c.z.data(), c.radius.data(), c.mu_r.data(), nullptr};
}

// Brute-force mutual dipoles within `cutoff` (all pairs, all x/z images), Jacobi to 1e-11;
// with `tail`, plus the mean-field slab tail beyond the cutoff (direct O(N²) sums, written
// independently of the library's prefix-sum version).
Forces reference_forces(const BrushConfiguration &c, double cutoff, int &sweeps, bool tail)
{
  const double tail_c = -mu0 / (4.0 * cutoff * c.box * c.box);
  auto tail_field = [&](std::size_t i, const std::vector<double> &p, double B[3], double dB[3]) {
    for (std::size_t k = 0; k < c.size(); ++k)
    {
      const double h = c.y[k] - c.y[i];
      if (std::abs(h) >= cutoff)
        continue;
      const double w = 1.0 - h * h / (cutoff * cutoff), dw = 2.0 * h / (cutoff * cutoff);
      const double q[3] = {-p[3 * k], 2.0 * p[3 * k + 1], -p[3 * k + 2]};
      for (int d = 0; d < 3; ++d)
      {
        B[d] += tail_c * w * q[d];
        dB[d] += tail_c * dw * q[d];
      }
    }
  };
  const std::size_t n = c.size();
  const long images = static_cast<long>(std::ceil(cutoff / c.box)) + 1;
  const long images_x = c.periodic_x ? images : 0;
  std::vector<double> p(3 * n), q(3 * n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const double B0[3] = {0.0, B_applied, 0.0};
    induced_moment(c.radius[i], clausius_mossotti(c.mu_r[i]), 0.0, B0, &p[3 * i]);
  }
  auto for_each_partner = [&](std::size_t i, auto &&visit) {
    for (std::size_t j = 0; j < n; ++j)
      for (long a = -images_x; a <= images_x; ++a)
        for (long b = -images; b <= images; ++b)
        {
          const double r[3] = {c.x[j] - c.x[i] + a * c.box, c.y[j] - c.y[i],
                               c.z[j] - c.z[i] + b * c.box};
          const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
          if (r2 > 0.0 && r2 < cutoff * cutoff)
            visit(j, r); // r from i to j
        }
  };
  for (sweeps = 1; sweeps <= 300; ++sweeps)
  {
    double change = 0.0, size = 0.0;
#pragma omp parallel for schedule(dynamic, 16) reduction(max : change, size)
    for (long i = 0; i < static_cast<long>(n); ++i)
    {
      double B[3] = {0.0, B_applied, 0.0}, dB[3] = {0, 0, 0};
      if (tail)
        tail_field(i, p, B, dB);
      for_each_partner(i, [&](std::size_t j, const double *r) {
        DipoleTensor::at(r).add_field(&p[3 * j], B);
      });
      induced_moment(c.radius[i], clausius_mossotti(c.mu_r[i]), 0.0, B, &q[3 * i]);
      double d2 = 0.0, p2 = 0.0;
      for (int d = 0; d < 3; ++d)
      {
        d2 += (q[3 * i + d] - p[3 * i + d]) * (q[3 * i + d] - p[3 * i + d]);
        p2 += q[3 * i + d] * q[3 * i + d];
      }
      change = std::max(change, d2);
      size = std::max(size, p2);
    }
    p.swap(q);
    if (std::sqrt(change / size) < 1e-11)
      break;
  }
  Forces f{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
#pragma omp parallel for schedule(dynamic, 16)
  for (long i = 0; i < static_cast<long>(n); ++i)
  {
    if (tail)
    {
      double B[3] = {0, 0, 0}, dB[3] = {0, 0, 0};
      tail_field(i, p, B, dB);
      f.fy[i] += p[3 * i] * dB[0] + p[3 * i + 1] * dB[1] + p[3 * i + 2] * dB[2];
    }
    for_each_partner(i, [&](std::size_t j, const double *r) {
      // Force on i from j: pair vector from j to i is −r.
      const double rji[3] = {-r[0], -r[1], -r[2]};
      double F[3];
      dipole_pair_force(rji, &p[3 * i], &p[3 * j], F);
      f.fx[i] += F[0];
      f.fy[i] += F[1];
      f.fz[i] += F[2];
    });
  }
  return f;
}

struct Evaluation
{
  Forces f;
  MagneticStats stats;
  double build_seconds = 0.0; // first call: list build + solve from the applied-field dipoles
  double eval_seconds = 0.0;  // repeat call: list reused, same cold start (best of two)
  double eval_cpu = 0.0;      // its process CPU time
};

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

Evaluation evaluate(const BrushConfiguration &c, MagneticSettings s)
{
  Evaluation e;
  const std::size_t n = c.size();
  e.f = {std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
  InducedDipoles magnetics(s, {c.box_x(), 0.0, c.box});
  ForceArrays out{e.f.fx.data(), e.f.fy.data(), e.f.fz.data()};
  auto t0 = std::chrono::steady_clock::now();
  e.stats = magnetics.compute(arrays(c), uniform_field(0.0, B_applied, 0.0), 0.0, out);
  e.build_seconds = seconds_since(t0);
  // Repeat (best of two) with the list already built and the same cold start: the cost of one
  // evaluation without the list build.
  std::vector<double> fx(n), fy(n), fz(n);
  ForceArrays scratch{fx.data(), fy.data(), fz.data()};
  e.eval_seconds = e.eval_cpu = 1e300;
  for (int rep = 0; rep < 2; ++rep)
  {
    magnetics.reset_dipoles();
    t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    magnetics.compute(arrays(c), uniform_field(0.0, B_applied, 0.0), 0.0, scratch);
    e.eval_cpu = std::min(e.eval_cpu, cpu_seconds() - c0);
    e.eval_seconds = std::min(e.eval_seconds, seconds_since(t0));
  }
  return e;
}

struct Errors
{
  double rms = 0.0;      // RMS |F − F_ref| / RMS |F_ref| over all beads
  double max = 0.0;      // max |F − F_ref| / RMS |F_ref|
  double plane = 0.0;    // |ΣF − ΣF_ref| / |ΣF_ref| over the beads on the plane
};

Errors compare(const BrushConfiguration &c, const Forces &f, const Forces &ref)
{
  Errors e;
  double ref2 = 0.0, err2 = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < c.size(); ++i)
  {
    const double dx = f.fx[i] - ref.fx[i], dy = f.fy[i] - ref.fy[i], dz = f.fz[i] - ref.fz[i];
    err2 += dx * dx + dy * dy + dz * dz;
    worst = std::max(worst, dx * dx + dy * dy + dz * dz);
    ref2 += ref.fx[i] * ref.fx[i] + ref.fy[i] * ref.fy[i] + ref.fz[i] * ref.fz[i];
  }
  e.rms = std::sqrt(err2 / ref2);
  e.max = std::sqrt(worst / (ref2 / c.size()));
  double S[3] = {0, 0, 0}, R[3] = {0, 0, 0};
  for (std::size_t i : c.on_plane)
  {
    S[0] += f.fx[i]; S[1] += f.fy[i]; S[2] += f.fz[i];
    R[0] += ref.fx[i]; R[1] += ref.fy[i]; R[2] += ref.fz[i];
  }
  e.plane = std::sqrt((S[0] - R[0]) * (S[0] - R[0]) + (S[1] - R[1]) * (S[1] - R[1]) +
                      (S[2] - R[2]) * (S[2] - R[2])) /
            std::sqrt(R[0] * R[0] + R[1] * R[1] + R[2] * R[2]);
  return e;
}

double plane_force_y(const BrushConfiguration &c, const Forces &f)
{
  double s = 0.0;
  for (std::size_t i : c.on_plane)
    s += f.fy[i];
  return s;
}

} // namespace

int main(int argc, char **argv)
{
  const std::size_t chains = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 100;
  const double ref_diameters = argc > 2 ? std::atof(argv[2]) : 32.0;
  const double a = 30e-6, mu_r = 3.9;
  const BrushConfiguration c = bench::make_brush(chains, 0.9e-3, a, 3e-6, 8, 16, mu_r, 2024);
  double mean_d = 0.0;
  for (double r : c.radius)
    mean_d += 2.0 * r / c.size();
  std::printf("# Timings: wall clock and process CPU time (run with OMP_NUM_THREADS=1 for a clean CPU "
              "figure on a shared machine).\n");
  std::printf("# Magnetics cost knobs: static brush, %zu beads in %zu chains (60 um +- 10 %%, "
              "mu_r %.1f), slab %.2f mm periodic in x and z, B = %.0f mT along the chains, "
              "%zu beads on the plane; %d OpenMP threads\n",
              c.size(), c.on_plane.size(), mu_r, c.box * 1e3, B_applied * 1e3, c.on_plane.size(),
              omp_get_max_threads());

  // --- References: brute force at ref_diameters (with the slab tail) and checks. ---
  int sweeps_ref = 0, sweeps_other = 0;
  auto t0 = std::chrono::steady_clock::now();
  const Forces ref = reference_forces(c, ref_diameters * mean_d, sweeps_ref, true);
  const double ref_seconds = seconds_since(t0);
  const Forces ref_half = reference_forces(c, 0.5 * ref_diameters * mean_d, sweeps_other, true);
  const Forces hard = reference_forces(c, ref_diameters * mean_d, sweeps_other, false);
  const Forces hard_half = reference_forces(c, 0.5 * ref_diameters * mean_d, sweeps_other, false);
  const Errors e_half = compare(c, ref_half, ref), e_hard = compare(c, hard, ref),
               e_hard_half = compare(c, hard_half, ref);
  std::printf("\n## Reference: brute-force mutual dipoles within R = %.0f diameters plus the "
              "mean-field slab tail beyond R (%d sweeps, %.1f s).\n"
              "Reference checks (RMS / plane-force difference from it): with tail at R/2: "
              "%.2e / %.2e; hard cutoff at R: %.2e / %.2e; hard cutoff at R/2: %.2e / %.2e.\n",
              ref_diameters, sweeps_ref, ref_seconds, e_half.rms, e_half.plane, e_hard.rms,
              e_hard.plane, e_hard_half.rms, e_hard_half.plane);

  // --- Cutoff study (mutual_dipole, tolerance 1e-8), hard cutoff and with the slab tail. ---
  for (bool with_tail : {false, true})
  {
    std::printf("\n## Cutoff (mutual_dipole, tolerance 1e-8, %s)\n",
                with_tail ? "with the slab tail correction" : "hard cutoff, as the papers");
    std::printf("| cutoff [d] | pairs | sweeps | first call [s] | repeat call [s] | repeat CPU [s] | RMS force err | "
                "max force err | plane-force err |\n|---|---|---|---|---|---|---|---|---|\n");
    for (double cut : {2.0, 4.0, 6.0, 8.0, 12.0, 16.0})
    {
      MagneticSettings s = hard_cutoff_settings();
      s.model = DipoleModel::mutual_dipole;
      s.cutoff_diameters = cut;
      s.tolerance = 1e-8;
      s.slab_tail_correction = with_tail;
      const Evaluation e = evaluate(c, s);
      const Errors err = compare(c, e.f, ref);
      std::printf("| %4.0f | %zu | %d | %.3f | %.3f | %.3f | %.2e | %.2e | %.2e |\n", cut, e.stats.pairs,
                  e.stats.sweeps, e.build_seconds, e.eval_seconds, e.eval_cpu, err.rms, err.max, err.plane);
      std::fflush(stdout);
    }
  }
  // Consistency: the library with its neighbour list and prefix-sum tail at the reference
  // radius against the brute force.
  {
    MagneticSettings s = hard_cutoff_settings();
    s.model = DipoleModel::mutual_dipole;
    s.cutoff_diameters = 0.5 * ref_diameters;
    s.tolerance = 1e-11;
    s.slab_tail_correction = true;
    const Evaluation e = evaluate(c, s);
    const Errors err = compare(c, e.f, ref_half);
    std::printf("(library vs brute force, both at %.0f d with tail: RMS %.2e, plane %.2e)\n",
                0.5 * ref_diameters, err.rms, err.plane);
  }

  // --- Models at 8 diameters. ---
  std::printf("\n## Models (cutoff 8 d, tolerance 1e-8): difference from `corrected`\n");
  MagneticSettings sc = hard_cutoff_settings();
  sc.model = DipoleModel::corrected;
  sc.cutoff_diameters = 8.0;
  sc.tolerance = 1e-8;
  const Evaluation corr = evaluate(c, sc);
  std::printf("| model | sweeps | repeat call [s] | repeat CPU [s] | plane force F_y [N] | RMS diff | plane-force diff |\n"
              "|---|---|---|---|---|---|---|\n");
  for (DipoleModel m : {DipoleModel::point_dipole, DipoleModel::mutual_dipole, DipoleModel::corrected})
  {
    MagneticSettings s = sc;
    s.model = m;
    const Evaluation e = m == DipoleModel::corrected ? corr : evaluate(c, s);
    const Errors err = compare(c, e.f, corr.f);
    std::printf("| %s | %d | %.3f | %.3f | %.4e | %.2e | %.2e |\n", to_string(m).c_str(), e.stats.sweeps,
                e.eval_seconds, e.eval_cpu, plane_force_y(c, e.f), err.rms, err.plane);
  }
  std::printf("(corrected pairs: %zu of %zu)\n", corr.stats.corrected_pairs, corr.stats.pairs);

  // --- Tolerance study (mutual_dipole, cutoff 8 d), against tolerance 1e-12. ---
  std::printf("\n## Mutual-induction tolerance (mutual_dipole, cutoff 8 d, from the "
              "applied-field dipoles)\n");
  MagneticSettings st = hard_cutoff_settings();
  st.model = DipoleModel::mutual_dipole;
  st.cutoff_diameters = 8.0;
  st.tolerance = 1e-12;
  const Evaluation tight = evaluate(c, st);
  std::printf("| tolerance | sweeps | repeat CPU [s] | RMS force err | plane-force err |\n"
              "|---|---|---|---|---|\n");
  for (double tol : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8})
  {
    MagneticSettings s = st;
    s.tolerance = tol;
    const Evaluation e = evaluate(c, s);
    const Errors err = compare(c, e.f, tight.f);
    std::printf("| %.0e | %d | %.3f | %.2e | %.2e |\n", tol, e.stats.sweeps, e.eval_cpu,
                err.rms, err.plane);
  }

  // --- Strip periodic along z only (the nip slab): the hard cutoff converges here. ---
  const BrushConfiguration strip =
    bench::make_brush(chains, 0.9e-3, a, 3e-6, 8, 16, mu_r, 2025, /*periodic_x=*/false);
  double strip_d = 0.0;
  for (double r : strip.radius)
    strip_d += 2.0 * r / strip.size();
  const Forces strip_ref = reference_forces(strip, ref_diameters * strip_d, sweeps_ref, false);
  std::printf("\n## Strip periodic along z only (%zu beads, x open over 0.9 mm): hard cutoff "
              "(mutual_dipole, tolerance 1e-8) against brute force at %.0f d\n",
              strip.size(), ref_diameters);
  std::printf("| cutoff [d] | pairs | repeat call [s] | repeat CPU [s] | RMS force err | max force err | plane-force err |\n"
              "|---|---|---|---|---|---|---|\n");
  for (double cut : {2.0, 4.0, 6.0, 8.0, 12.0, 16.0})
  {
    MagneticSettings s = hard_cutoff_settings();
    s.model = DipoleModel::mutual_dipole;
    s.cutoff_diameters = cut;
    s.tolerance = 1e-8;
    const Evaluation e = evaluate(strip, s);
    const Errors err = compare(strip, e.f, strip_ref);
    std::printf("| %4.0f | %zu | %.3f | %.3f | %.2e | %.2e | %.2e |\n", cut, e.stats.pairs,
                e.eval_seconds, e.eval_cpu, err.rms, err.max, err.plane);
    std::fflush(stdout);
  }
  return 0;
}
