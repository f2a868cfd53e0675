// The magnetic share of the DEM step time on the paper scenes, measured side by side in one
// run: the same system stepped without magnetics (contact-only), then with the magnetics at
// the case defaults (cell-multipole far field, refresh 5 µs = 250 steps, staleness 5 % of a
// radius), then with the previous default (hard cutoff 12 d). Two shares: against the
// contact-only phase (wall clock per step), and — robust to the machine's load changing
// between phases — the engine's own clock of the magnetic term against everything else in
// the same steps.
//
// Scenes (mode `brush`, the default): the case's walls and materials with a standing brush
// in place of the insertion — chains of touching 60 µm beads (8–16 long, leaning a few
// degrees) on the stage (compression box, 2 × 2 mm periodic) or radially on the sleeve over
// the case's 30° insertion arc (nip, 1 mm slab; the sleeve turns and drags them). Mode
// `loose`: the case's own insertion (a loose cloud, before settling). The applied field is
// uniform (the nip's roller grid needs the field solver; a grid lookup is a small part of
// a refresh): along the stage normal, or radial at the middle of the nip arc.
//
//   bench_magnetic_step_share [nip_carriers] [compression_carriers] [steps] [brush|loose]
#include "dem/dem_system.h"
#include "dem/force_terms/magnetic_force_term.h"
#include "tests/magnetics/brush_configuration.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"

#include <omp.h>

#include <cmath>

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace magbrush;
using namespace magbrush::magnetics;

namespace {

double time_steps(dem::DemSystem &system, long steps)
{
  const double t0 = omp_get_wtime();
  for (long k = 0; k < steps; ++k)
    system.step();
  return (omp_get_wtime() - t0) / steps;
}

// Where a brush bead (plane coordinates: x along the plane, y height, z periodic) goes.
using Placement = std::function<dem::Vector3(double, double, double)>;

void scene(const char *label, const std::string &file, long carriers, long steps,
           const Vec3 &direction, double magnitude, bool loose, double width, const Placement &place)
{
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/" + file,
                           {"populations.carrier.count=" + std::to_string(carriers),
                            "dem.settle_time=0 s"});
  std::printf("\n%s: %ld carriers, %ld steps of %.3g s per phase, refresh %.3g s, %d threads\n\n",
              label, carriers, steps, c.dem.time_step, c.dem.magnetic_refresh, omp_get_max_threads());
  std::printf("| phase | s/step | share vs contact-only phase | share in the same steps | evaluations | s/evaluation | sweeps | far passes | last evaluation: lists / tensors / far / sweeps / forces [s] |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  dem::DemSystem system(c);
  if (loose)
    system.insert_particles();
  else
  {
    // Chains of 8–16 beads: about 12 per chain on average.
    const double density = c.material(c.populations[0].material).density;
    const auto brush = magnetics::bench::make_brush(static_cast<std::size_t>(carriers / 12),
                                                    c.dem.periodic_length > 0 ? c.dem.periodic_length : 2e-3,
                                                    30e-6, 3e-6, 8, 16, 3.9, 5, width == 0.0, width);
    for (std::size_t k = 0; k < brush.size(); ++k)
      system.particles().add(place(brush.x[k], brush.y[k], brush.z[k]), brush.radius[k], density, 0, 0.0);
    std::printf("(standing brush: %zu beads)\n\n", brush.size());
  }
  system.initialize();
  time_steps(system, 20); // first neighbour lists, caches
  const double contact = time_steps(system, steps);
  std::printf("| contact only | %.3e | — | — | 0 | — | — | — | — |\n", contact);
  std::fflush(stdout);

  auto add = [&](const char *name, MagneticSettings s) {
    auto owned = std::make_unique<MagneticForceTerm>(
      c, s, AppliedMagneticField::uniform(direction, magnitude), system.box().length);
    MagneticForceTerm *term = owned.get();
    system.add_force_term(std::move(owned));
    const double t0 = omp_get_wtime();
    system.step(); // the first (cold) evaluation
    const double cold = omp_get_wtime() - t0;
    const long before = term->evaluations();
    // The engine's own phase clocks over the same steps: magnetic term against everything
    // else (contacts, walls, neighbour lists, integration, other terms), robust to the load
    // of the machine changing between phases.
    const dem::PhaseTimes p0 = system.phase_times();
    const double with = time_steps(system, steps);
    const dem::PhaseTimes p1 = system.phase_times();
    const std::size_t me = p1.terms.size() - 1;
    const double magnetic = p1.terms[me] - p0.terms[me];
    double rest = (p1.neighbour - p0.neighbour) + (p1.particle_contacts - p0.particle_contacts) +
                  (p1.wall_contacts - p0.wall_contacts) + (p1.integrate - p0.integrate) +
                  (p1.guards - p0.guards);
    for (std::size_t t = 0; t < me; ++t)
      rest += p1.terms[t] - p0.terms[t];
    const long evaluations = term->evaluations() - before;
    const double contact_now = contact; // measured above, same system
    const MagneticStats &st = term->last_stats();
    std::printf("| %s | %.3e | %+.0f %% | %+.0f %% | %ld | %.3f (cold %.3f) | %d | %d | %.3f / %.3f / %.3f / %.3f / %.3f |\n",
                name, with, 100.0 * (with - contact_now) / contact_now, 100.0 * magnetic / rest,
                evaluations,
                evaluations ? (with - contact_now) * steps / evaluations : 0.0, cold, st.sweeps,
                st.far_passes, st.time_lists, st.time_tensors, st.time_far, st.time_sweeps,
                st.time_forces);
    std::fflush(stdout);
    term->set_enabled(false);
    return term;
  };
  MagneticSettings defaults = MagneticSettings::from_case(c.dem);
  add("magnetics, defaults (cell_multipole)", defaults);
  MagneticSettings old = defaults;
  old.far_field = FarField::none;
  old.cutoff_diameters = 12.0;
  add("magnetics, hard cutoff 12 d (old default)", old);

  // Refresh interval as an accuracy knob: hold the forces of one evaluation (no refresh, no
  // staleness trigger) and compare them, k steps later, with a fresh evaluation at the
  // current positions (same settings: only the holding error is measured).
  MagneticSettings hold = defaults;
  hold.refresh_interval = 1.0;
  hold.staleness_fraction = 1e9;
  auto owned = std::make_unique<MagneticForceTerm>(
    c, hold, AppliedMagneticField::uniform(direction, magnitude), system.box().length);
  MagneticForceTerm *term = owned.get();
  system.add_force_term(std::move(owned));
  system.step();
  const AppliedMagneticField field = AppliedMagneticField::uniform(direction, magnitude);
  const double t_start = system.time();
  std::printf("\nHeld forces against fresh ones (same settings), k steps after an evaluation:\n\n");
  std::printf("| steps held | time [us] | max bead displacement / radius | RMS |F_held − F_fresh| / RMS |F_fresh| | max bead error / RMS |F_fresh| |\n");
  std::printf("|---|---|---|---|---|\n");
  auto &p = system.particles();
  std::vector<double> x0(p.x), y0(p.y), z0(p.z);
  std::vector<std::int32_t> id0(p.id);
  long done = 1;
  for (long k : {25L, 100L, 250L, 500L, 1000L})
  {
    for (; done < k; ++done)
      system.step();
    const std::size_t n = p.size();
    // Displacement since the evaluation (by particle id: the engine re-sorts).
    std::vector<double> X(3 * n);
    for (std::size_t b = 0; b < n; ++b)
    {
      const std::size_t i = static_cast<std::size_t>(p.id[b]);
      X[3 * i] = p.x[b];
      X[3 * i + 1] = p.y[b];
      X[3 * i + 2] = p.z[b];
    }
    double worst_move = 0.0;
    for (std::size_t b = 0; b < n; ++b)
    {
      const std::size_t i = static_cast<std::size_t>(id0[b]);
      const double dx = X[3 * i] - x0[b], dy = X[3 * i + 1] - y0[b], dz = X[3 * i + 2] - z0[b];
      double dr[3] = {dx, dy, dz};
      for (int a = 0; a < 3; ++a) // a wrap across a periodic face is not a move
        if (system.box().length[a] > 0.0)
          dr[a] -= system.box().length[a] * std::round(dr[a] / system.box().length[a]);
      worst_move = std::max(worst_move, std::sqrt(dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2]) / 30e-6);
    }
    std::vector<double> hx(n, 0.0), hy(n, 0.0), hz(n, 0.0), fx(n, 0.0), fy(n, 0.0), fz(n, 0.0);
    term->dipoles().add_held_forces({hx.data(), hy.data(), hz.data()});
    std::vector<double> mu(n, 3.9);
    MagneticSettings fresh_settings = defaults;
    fresh_settings.refresh_interval = 0.0;
    InducedDipoles fresh(fresh_settings, system.box().length);
    const AppliedFieldFunction lookup = [&field](const double x[3], double B[3], double g[3][3]) {
      Vec3 Bv;
      std::array<Vec3, 3> G;
      field.evaluate({x[0], x[1], x[2]}, 0.0, Bv, G);
      for (int a = 0; a < 3; ++a)
      {
        B[a] = Bv[a];
        for (int b = 0; b < 3; ++b)
          g[a][b] = G[a][b];
      }
    };
    fresh.compute({n, p.x.data(), p.y.data(), p.z.data(), p.radius.data(), mu.data(), nullptr}, lookup,
                  0.0, {fx.data(), fy.data(), fz.data()});
    double e2 = 0.0, f2 = 0.0, emax = 0.0;
    for (std::size_t b = 0; b < n; ++b)
    {
      const double e = std::pow(hx[b] - fx[b], 2) + std::pow(hy[b] - fy[b], 2) + std::pow(hz[b] - fz[b], 2);
      e2 += e;
      emax = std::max(emax, e);
      f2 += fx[b] * fx[b] + fy[b] * fy[b] + fz[b] * fz[b];
    }
    std::printf("| %ld | %.2f | %.3f | %.2e | %.2e |\n", k, (system.time() - t_start) * 1e6, worst_move,
                std::sqrt(e2 / f2), std::sqrt(emax / (f2 / n)));
    std::fflush(stdout);
  }
}

} // namespace

int main(int argc, char **argv)
{
  const long nip = argc > 1 ? std::atol(argv[1]) : 12300;
  const long compression = argc > 2 ? std::atol(argv[2]) : 4420;
  const long steps = argc > 3 ? std::atol(argv[3]) : 500;
  const bool loose = argc > 4 && std::string(argv[4]) == "loose";
  // Nip: chains standing radially on the sleeve (radius 12.5 mm) from −45° over 6.5 mm of arc.
  const double R = 12.5e-3, theta0 = -45.0 * 3.14159265358979 / 180.0;
  const double mid = theta0 + 3.25e-3 / R;
  scene("Nip (cases/kawamoto_nip.yaml), uniform 0.1 T radial at the arc's middle",
        "kawamoto_nip.yaml", nip, steps, {std::cos(mid), std::sin(mid), 0.0}, 0.1, loose, 6.5e-3,
        [&](double x, double y, double z) {
          const double theta = theta0 + x / R, rho = R + y;
          return dem::Vector3{rho * std::cos(theta), rho * std::sin(theta), z};
        });
  // Compression: chains standing on the stage z = 0 of the 2 × 2 mm periodic box.
  scene("Compression (cases/kawamoto_brush_compression.yaml), 130 mT along z",
        "kawamoto_brush_compression.yaml", compression, steps, {0.0, 0.0, 1.0}, 0.13, loose, 0.0,
        [](double x, double y, double z) { return dem::Vector3{x, z, y}; });
  return 0;
}
