// Accuracy against cost of the magnetic field grid: for each grid spacing (Δr, Δθ), the
// maximum error of B and of ∇|B|² on a roller-like field (5 Gaussian poles, sleeve radius
// 12.5 mm, annulus 12.5..16 mm; exact multipole-ring reference), the memory the grid takes,
// and the time of one B+∇B lookup (Google Benchmark, random points in the annulus).
// Errors are relative to the largest exact value over the annulus (|B|max, |∇|B|²|max).
// Prints its table and exits 0; nothing here is asserted.
#include "fields/applied_magnetic_field.h"
#include "fields/cartesian_field_interpolator.h"
#include "tests/fields/exact_multipole.h"
#include "fields/polar_field_interpolator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <memory>
#include <string>

using namespace magbrush;
using namespace magbrush::testing;

namespace {

constexpr double r_min = 12.5e-3, r_max = 16e-3, deg = M_PI / 180.0;

struct Spacing
{
  double dr;     // [m]
  double dtheta; // [rad]
};

// Joint refinement, then mixed rows that show which of the two spacings limits the error.
const std::vector<Spacing> spacings = {
    {200e-6, 1.0 * deg},  {100e-6, 0.5 * deg}, {50e-6, 0.25 * deg}, {25e-6, 0.125 * deg},
    {100e-6, 0.25 * deg}, {75e-6, 0.5 * deg},  {50e-6, 1.0 * deg},  {50e-6, 0.5 * deg},
    {25e-6, 0.5 * deg},   {50e-6, 0.125 * deg}};

PolarGrid make_grid(const MultipoleField &f, const Spacing &s)
{
  const int n_r = 1 + static_cast<int>(std::ceil((r_max - r_min) / s.dr - 1e-9));
  const int n_theta = static_cast<int>(std::ceil(2 * M_PI / s.dtheta - 1e-9));
  return sample_polar_grid(r_min, r_max, n_r, n_theta,
                           [&](double x, double y) { return f.A(x, y); });
}

struct Accuracy
{
  double B = 0, gradB2 = 0, B_sleeve = 0;
};

Accuracy measure(const PolarFieldInterpolator &interp, const MultipoleField &f,
                 const std::vector<std::array<double, 2>> &points)
{
  Accuracy a;
  double B_max = 0, G_max = 0;
  for (const auto &p : points)
  {
    const auto e = f.B(p[0], p[1]);
    Vec3 B;
    std::array<Vec3, 3> g;
    interp.evaluate({p[0], p[1], 0}, B, g);
    const double Gx = 2 * (e.B[0] * e.gradB[0][0] + e.B[1] * e.gradB[1][0]);
    const double Gy = 2 * (e.B[0] * e.gradB[0][1] + e.B[1] * e.gradB[1][1]);
    const double Gix = 2 * (B[0] * g[0][0] + B[1] * g[1][0]);
    const double Giy = 2 * (B[0] * g[0][1] + B[1] * g[1][1]);
    B_max = std::max(B_max, std::hypot(e.B[0], e.B[1]));
    G_max = std::max(G_max, std::hypot(Gx, Gy));
    const double eB = std::hypot(B[0] - e.B[0], B[1] - e.B[1]);
    a.B = std::max(a.B, eB);
    a.gradB2 = std::max(a.gradB2, std::hypot(Gix - Gx, Giy - Gy));
    if (std::hypot(p[0], p[1]) < r_min + 0.5e-3)
      a.B_sleeve = std::max(a.B_sleeve, eB);
  }
  a.B /= B_max;
  a.gradB2 /= G_max;
  a.B_sleeve /= B_max;
  return a;
}

// Random lookup points (a fixed cycle: the DEM's particles are spread over the annulus).
const std::vector<Vec3> &lookup_points()
{
  static const std::vector<Vec3> points = [] {
    std::vector<Vec3> v;
    for (const auto &p : sample_annulus(r_min + 1e-6, r_max - 1e-6, 4096, 99))
      v.push_back({p[0], p[1], 0.0});
    return v;
  }();
  return points;
}

template <typename Lookup>
void time_lookups(benchmark::State &state, Lookup lookup)
{
  const auto &points = lookup_points();
  size_t k = 0;
  Vec3 B;
  std::array<Vec3, 3> g;
  for (auto _ : state)
  {
    lookup(points[k], B, g);
    benchmark::DoNotOptimize(B);
    benchmark::DoNotOptimize(g);
    k = (k + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}

// Five repetitions each; the table takes the fastest (CPU time), the figure least disturbed
// by other processes on a shared machine.
void timed(benchmark::internal::Benchmark *b)
{
  b->MinTime(0.1)->Repetitions(5)->DisplayAggregatesOnly(true)->ComputeStatistics(
      "min", [](const std::vector<double> &v) { return *std::min_element(v.begin(), v.end()); });
}

// Collects the fastest time per iteration of each benchmark by name, and prints the usual
// console report too.
class Collector : public benchmark::ConsoleReporter
{
public:
  std::map<std::string, double> ns;
  void ReportRuns(const std::vector<Run> &runs) override
  {
    for (const auto &run : runs)
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "min")
        ns[run.run_name.function_name] = run.GetAdjustedCPUTime(); // default unit: ns
    ConsoleReporter::ReportRuns(runs);
  }
};

std::string label(const Spacing &s)
{
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "grid dr=%.0fum dth=%.3fdeg", s.dr * 1e6, s.dtheta / deg);
  return buffer;
}

} // namespace

int main(int argc, char **argv)
{
  benchmark::Initialize(&argc, argv);
  const MultipoleField field = roller_like_field();
  const auto points = sample_annulus(r_min, r_max, 40000, 2024);

  struct Row
  {
    Spacing s;
    int n_r, n_theta;
    size_t bytes;
    Accuracy a;
    std::shared_ptr<const PolarFieldInterpolator> interp;
  };
  std::vector<Row> rows;
  for (const Spacing &s : spacings)
  {
    const PolarGrid grid = make_grid(field, s);
    auto interp = std::make_shared<const PolarFieldInterpolator>(grid);
    rows.push_back({s, grid.n_r, grid.n_theta, interp->memory_bytes(), measure(*interp, field, points),
                    interp});
    timed(benchmark::RegisterBenchmark(label(s).c_str(), [interp](benchmark::State &st) {
      time_lookups(st, [&](const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &g) { interp->evaluate(x, B, g); });
    }));
  }
  // The other paths a DEM step may take, for comparison. `default` is the grid of
  // FieldSettings' default spacing (50 µm, 0.25°: row 3).
  const auto default_grid = rows[2].interp;
  const auto applied = AppliedMagneticField::roller(default_grid);
  timed(benchmark::RegisterBenchmark("AppliedMagneticField roller (default grid)", [&](benchmark::State &st) {
    time_lookups(st, [&](const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &g) { applied.evaluate(x, 1.0, B, g); });
  }));
  // The DEM sorts its particles spatially: consecutive lookups hit neighbouring cells.
  static std::vector<Vec3> sorted = lookup_points();
  std::sort(sorted.begin(), sorted.end(), [](const Vec3 &a, const Vec3 &b) {
    return std::atan2(a[1], a[0]) < std::atan2(b[1], b[0]);
  });
  timed(benchmark::RegisterBenchmark("default grid, points in spatial order", [&](benchmark::State &st) {
    size_t k = 0;
    Vec3 B;
    std::array<Vec3, 3> g;
    for (auto _ : st)
    {
      default_grid->evaluate(sorted[k], B, g);
      benchmark::DoNotOptimize(B);
      benchmark::DoNotOptimize(g);
      k = (k + 1) & 4095;
    }
  }));
  const auto uniform = AppliedMagneticField::uniform({0, 0, 1}, 0.13, 1e-3);
  timed(benchmark::RegisterBenchmark("AppliedMagneticField uniform+ramp", [&](benchmark::State &st) {
    time_lookups(st, [&](const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &g) { uniform.evaluate(x, 5e-4, B, g); });
  }));
  const auto tail_interp = default_grid;
  timed(benchmark::RegisterBenchmark("multipole tail beyond r_max", [&](benchmark::State &st) {
    time_lookups(st, [&](const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &g) {
      tail_interp->evaluate({1.2 * x[0], 1.2 * x[1], 0}, B, g); // r in 15..19.2 mm: mostly the tail
    });
  }));
  const CartesianFieldInterpolator electric(sample_cartesian_grid(
      -1e-3, 1e-3, 201, 12.5e-3, 13e-3, 51, [](double x, double y) { return 600 * x * y * 1e3; }));
  timed(benchmark::RegisterBenchmark("electric E lookup (Cartesian)", [&](benchmark::State &st) {
    time_lookups(st, [&](const Vec3 &x, Vec3 &B, std::array<Vec3, 3> &) {
      electric.evaluate({x[0] * 0.05, 12.5e-3 + 0.02 * (x[1] + 16e-3), 0}, B);
    });
  }));

  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);

  std::printf("\nMagnetic field grid: accuracy against cost (roller-like field, 5 poles, annulus "
              "12.5..16 mm, %zu random points)\n",
              points.size());
  std::printf("errors relative to max|B| = exact maximum over the annulus; 'near sleeve' = r < 13 mm\n");
  std::printf("%9s %9s %6s %6s %10s %12s %12s %12s %10s\n", "dr[um]", "dth[deg]", "n_r", "n_th",
              "memory", "err B", "err B(slv)", "err grad|B|2", "ns/lookup");
  for (const Row &r : rows)
  {
    const auto it = collector.ns.find(label(r.s));
    std::printf("%9.1f %9.3f %6d %6d %8.2fMB %12.3e %12.3e %12.3e %10.1f\n", r.s.dr * 1e6,
                r.s.dtheta / deg, r.n_r, r.n_theta, r.bytes / 1048576.0, r.a.B, r.a.B_sleeve,
                r.a.gradB2, it == collector.ns.end() ? NAN : it->second);
  }
  std::printf("\ntargets: err B <= 1e-4, err grad|B|^2 <= 1e-3, <= 100 ns per B+gradB lookup\n");
  for (const char *name : {"AppliedMagneticField roller (default grid)",
                           "default grid, points in spatial order", "AppliedMagneticField uniform+ramp",
                           "multipole tail beyond r_max", "electric E lookup (Cartesian)"})
    std::printf("%-45s %8.1f ns\n", name, collector.ns[name]);
  std::printf("(ns: fastest of 5 repetitions, CPU time per lookup, random points unless said)\n");

  // Sharper poles (α = 40 /rad²: ~30° wide) need more harmonics: the same spacings again.
  const MultipoleField sharp = roller_like_field(40.0);
  std::printf("\nSharper poles (alpha = 40 /rad^2), same annulus\n");
  std::printf("%9s %9s %12s %12s\n", "dr[um]", "dth[deg]", "err B", "err grad|B|2");
  for (const Spacing &s : {spacings[1], spacings[2], spacings[7], spacings[8], spacings[3]})
  {
    const PolarFieldInterpolator interp(make_grid(sharp, s));
    const Accuracy a = measure(interp, sharp, points);
    std::printf("%9.1f %9.3f %12.3e %12.3e\n", s.dr * 1e6, s.dtheta / deg, a.B, a.gradB2);
  }

  // The nip grid (FieldSettings::grid_electric_spacing, default 10 µm): a harmonic potential
  // like the nip's — bias across a 400 µm gap over a latent image of 300 µm period —
  // Φ = V y/g + φ1 cos(kx) sinh(k(g − y))/sinh(kg) on the window |x| ≤ 1.5 mm, 0 ≤ y ≤ g.
  const double gap = 400e-6, V = -600.0, phi1 = 150.0, k = 2 * M_PI / 300e-6;
  const auto phi = [&](double x, double y) {
    return V * y / gap + phi1 * std::cos(k * x) * std::sinh(k * (gap - y)) / std::sinh(k * gap);
  };
  const auto E_exact = [&](double x, double y) -> std::array<double, 2> {
    const double sh = std::sinh(k * gap);
    return {phi1 * k * std::sin(k * x) * std::sinh(k * (gap - y)) / sh,
            -V / gap + phi1 * k * std::cos(k * x) * std::cosh(k * (gap - y)) / sh};
  };
  std::printf("\nElectric nip grid: |x| <= 1.5 mm, 0 <= y <= 400 um; errors relative to max|E|\n");
  std::printf("%9s %8s %10s %12s %8s\n", "h[um]", "nodes", "memory", "err E", "order");
  double previous = 0.0;
  for (double h : {40e-6, 20e-6, 10e-6, 5e-6})
  {
    const int nx = 1 + static_cast<int>(std::lround(3e-3 / h)), ny = 1 + static_cast<int>(std::lround(gap / h));
    const CartesianFieldInterpolator interp(sample_cartesian_grid(-1.5e-3, 1.5e-3, nx, 0.0, gap, ny, phi));
    double err = 0, scale = 0;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> ux(-1.5e-3, 1.5e-3), uy(0.0, gap);
    for (int n = 0; n < 40000; ++n)
    {
      const double x = ux(rng), y = uy(rng);
      const auto e = E_exact(x, y);
      const Vec3 E = interp.field({x, y, 0});
      err = std::max(err, std::hypot(E[0] - e[0], E[1] - e[1]));
      scale = std::max(scale, std::hypot(e[0], e[1]));
    }
    err /= scale;
    std::printf("%9.1f %8d %8.2fMB %12.3e %8.2f\n", h * 1e6, nx * ny, interp.memory_bytes() / 1048576.0,
                err, previous > 0 ? std::log2(previous / err) : NAN);
    previous = err;
  }
  benchmark::Shutdown();
  return 0;
}
