// Benchmark of Kawamoto's compression test. Two modes:
//
//   bench_compression_study full [UNTIL_MS]
//       the case cases/kawamoto_brush_compression.yaml at its defaults (60 um, 4,420 beads,
//       2 x 2 mm², the project's magnetics at their defaults, 20 ns step, plate down at 0.1 m/s to
//       0.4 mm, then slid 1.5 mm): wall time, magnetic share, normal force against brush length
//       and the sliding ratio. With UNTIL_MS the run stops there (dem.duration) and the table
//       says so — a timing sample when the whole run does not fit.
//   bench_compression_study diameters [BOX_IN_DIAMETERS [SEEDS [defaults|paper]]]
//       the reduced protocol of the regression test (compression_run.h) with the field sweep and
//       the slide, for 42, 50 and 60 um in periodic squares of BOX_IN_DIAMETERS mean diameters
//       (default 12), SEEDS insertions each (default 1), with the project's default magnetics
//       (untruncated cell-multipole far field) or the paper's (cutoff 4 d + slab tail): the
//       3-diameter table (forces in mN, densities, force per bead, spacing, F_t/F_n, the field
//       exponent) and the pooled ratios to Kawamoto's scaling.
//
// Prints tables, asserts nothing, exits 0 (a failed run is reported in the table).
#include "tests/scenes/compression/compression_run.h"

#include "case/case_parser.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

using namespace magbrush;
using namespace magbrush::compression_test;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string &what)
{
  return fs::temp_directory_path() / ("magbrush_bench_compression_" + what + "_" + std::to_string(::getpid()));
}

void full(double until_ms)
{
  std::vector<std::string> o;
  const fs::path dir = scratch("full");
  o.push_back("output.directory=" + dir.string());
  o.push_back("dem.output_interval=0s");
  if (until_ms > 0)
    o.push_back("dem.duration=" + std::to_string(until_ms) + "ms");
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml", o);
  std::printf("# Kawamoto compression test at the case defaults: %s um x %ld beads on %.1f x %.1f mm², "
              "far field %s (cutoff %.0f d if none), refresh %.3g us, step %.3g ns, simulated %.3g ms%s\n",
              std::to_string(std::lround(c.populations[0].diameter_mean * 1e6)).c_str(), c.populations[0].count,
              c.dem.periodic_length_x * 1e3, c.dem.periodic_length_y * 1e3, c.dem.magnetic_far_field.c_str(),
              c.dem.magnetic_cutoff, c.dem.magnetic_refresh * 1e6, c.dem.time_step * 1e9, c.dem.duration * 1e3,
              until_ms > 0 ? " (STOPPED EARLY: a timing sample, not the whole test)" : "");
  RunResult r;
  try
  {
    r = run_case(c, (dir / "dem").string());
  }
  catch (const std::exception &e)
  {
    std::printf("run failed: %s\n", e.what());
    fs::remove_all(dir);
    return;
  }
  const double steps = c.dem.duration / c.dem.time_step;
  std::printf(
      "\n| beads | simulated [ms] | wall [s] | magnetic share | wall per simulated ms [s] | particle-steps/s |\n"
      "|---|---|---|---|---|---|\n| %ld | %.3g | %.1f | %.1f %% | %.1f | %.3g |\n",
      r.beads, c.dem.duration * 1e3, r.wall_s, 100 * r.magnetic_s / r.wall_s, r.wall_s / (c.dem.duration * 1e3),
      steps * static_cast<double>(r.beads) / r.wall_s);
  std::printf("\nnormal force against brush length (130 mT, plate at 0.1 m/s):\n\n"
              "| brush length [mm] | F_n [mN] | pressure [kPa] | touching | density [1/mm²] | force/bead [uN] | "
              "l/sqrt(n) [um] |\n|---|---|---|---|---|---|---|\n");
  for (double L = 1.15; L > 0.37; L -= 0.05)
  {
    std::vector<dem::PlateCompressionRow> in;
    for (const auto &row : r.rows)
      if (row.time > 0.5e-3 && row.time < 8.5e-3 && std::abs(row.gap - L * 1e-3) <= 0.025e-3)
        in.push_back(row);
    const WindowMean w = mean_over(in, {0.0, 1.0});
    if (w.rows == 0)
      continue;
    std::printf("| %.2f | %.4f | %.3f | %.1f | %.1f | %.2f | %.1f |\n", L, w.fn * 1e3, w.fn / r.area * 1e-3, w.touching,
                w.touching / r.area * 1e-6, w.touching > 0 ? w.fn / w.touching * 1e6 : 0.0,
                w.touching > 0 ? std::sqrt(r.area / w.touching) * 1e6 : 0.0);
  }
  const WindowMean s = mean_over(r.rows, {12.5e-3, 14.5e-3});
  if (s.rows > 0)
    std::printf("\nsliding at 0.4 mm (last 0.5 mm of 1.5 mm): F_n %.4f mN, F_t %.4f mN, F_t/F_n %.3f\n", s.fn * 1e3,
                s.ft * 1e3, s.ft / s.fn);
  fs::remove_all(dir);
}

void diameters(double box_in_d, int seeds, bool paper)
{
  std::printf("# Kawamoto compression, reduced protocol (compression_run.h) in squares of %.0f mean diameters, "
              "%d insertion(s) per size, %s magnetics, step 35 ns\n\n",
              box_in_d, seeds,
              paper ? "the paper's (cutoff 4 d + slab tail)" : "the project's default (cell-multipole far field)");
  std::printf("| d [um] | box [mm] | beads | wall [s] | magnetic | F_n 0.95 mm [mN] | F_n 0.65 mm [mN] | "
              "p(0.6 mm) [kPa] | density [1/mm²] | force/bead [uN] | l/sqrt(n) [um] | F_t/F_n | k (F~B^k, 20-50 mT) |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  struct Row
  {
    int d;
    double fn, touching, area; // at the hold, 0.6 mm and 130 mT
  };
  std::vector<Row> rows;
  for (int d : {42, 50, 60})
  {
    const double box = std::round(box_in_d * d * 1e-3 * 100.0) / 100.0; // mm, 0.01 mm steps
    for (int seed = 1; seed <= seeds; ++seed)
    {
      ReducedScene s;
      s.diameter_um = d;
      s.box_mm = box;
      s.seed = static_cast<unsigned long>(seed);
      s.paper_magnetics = paper;
      const fs::path dir = scratch(std::to_string(d) + "_" + std::to_string(seed));
      RunResult r;
      try
      {
        r = run_case(reduced_case(s, dir.string()), (dir / "dem").string());
      }
      catch (const std::exception &e)
      {
        std::printf("| %d | %.2f | run failed: %s |\n", d, box, e.what());
        fs::remove_all(dir);
        continue;
      }
      const WindowMean top = mean_at_length(r.rows, 0.90e-3, 1.0e-3), low = mean_at_length(r.rows, 0.60e-3, 0.70e-3);
      const WindowMean h = mean_over(r.rows, hold_130), sl = mean_over(r.rows, slide_steady);
      std::vector<double> b, f;
      for (const auto &fh : field_holds())
        if (fh.field_mT <= 50)
        {
          const WindowMean m = mean_over(r.rows, fh.w);
          b.push_back(m.field);
          f.push_back(m.fn);
        }
      const double density = h.touching / r.area, per_bead = h.fn / h.touching;
      std::printf("| %d | %.2f | %ld | %.1f | %.0f %% | %.4f | %.4f | %.3f | %.1f | %.2f | %.1f | %.3f | %.3f |\n", d,
                  box, r.beads, r.wall_s, 100 * r.magnetic_s / r.wall_s, top.fn * 1e3, low.fn * 1e3,
                  h.fn / r.area * 1e-3, density * 1e-6, per_bead * 1e6, 1e6 / std::sqrt(density), sl.ft / sl.fn,
                  power_law_exponent(b, f));
      std::fflush(stdout);
      rows.push_back({d, h.fn, h.touching, r.area});
      fs::remove_all(dir);
    }
  }
  // Pool the insertions of each size (total force, beads and area), then compare the sizes.
  struct Pool
  {
    int d;
    double fn = 0, touching = 0, area = 0;
  };
  std::vector<Pool> pools;
  for (const auto &r : rows)
  {
    if (pools.empty() || pools.back().d != r.d)
      pools.push_back({r.d});
    pools.back().fn += r.fn;
    pools.back().touching += r.touching;
    pools.back().area += r.area;
  }
  if (pools.size() < 2)
    return;
  double pm = 0;
  for (const auto &p : pools)
    pm += p.fn / p.area / static_cast<double>(pools.size());
  const Pool &ref = pools.back(); // 60 um
  std::printf("\npooled insertions, relative to %d um: pressure / mean pressure, density x d² and force per bead / d² "
              "(1 = Kawamoto's scaling)\n\n| d [um] | p [kPa] | p / mean | density [1/mm²] | density d² | "
              "force/bead [uN] | force/bead / d² |\n|---|---|---|---|---|---|---|\n",
              ref.d);
  for (const auto &p : pools)
  {
    const double d2 = (static_cast<double>(p.d) / ref.d) * (static_cast<double>(p.d) / ref.d);
    const double density = p.touching / p.area, ref_density = ref.touching / ref.area;
    const double per_bead = p.fn / p.touching, ref_per_bead = ref.fn / ref.touching;
    std::printf("| %d | %.3f | %.3f | %.1f | %.3f | %.2f | %.3f |\n", p.d, p.fn / p.area * 1e-3, p.fn / p.area / pm,
                density * 1e-6, density * d2 / ref_density, per_bead * 1e6, per_bead / d2 / ref_per_bead);
  }
}

} // namespace

int main(int argc, char **argv)
{
  const std::string mode = argc > 1 ? argv[1] : "full";
  if (mode == "full")
    full(argc > 2 ? std::atof(argv[2]) : 0.0);
  else if (mode == "diameters")
    diameters(argc > 2 ? std::atof(argv[2]) : 12.0, argc > 3 ? std::atoi(argv[3]) : 1,
              argc > 4 && std::string(argv[4]) == "paper");
  else
    std::printf(
        "usage: bench_compression_study full [UNTIL_MS] | diameters [BOX_IN_DIAMETERS [SEEDS [defaults|paper]]]\n");
  return 0;
}
