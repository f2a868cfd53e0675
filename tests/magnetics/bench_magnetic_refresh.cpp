// The magnetic refresh interval as an accuracy knob (needs the DEM engine): the same short
// run of Kawamoto's compression scene (field on at once) with the magnetics re-evaluated
// every step (the reference) and held for longer intervals, with and without the staleness
// check. Prints the state difference after the run and the time per step.
//
//   bench_magnetic_refresh [particles] [steps]
#include "dem/dem_system.h"
#include "dem/force_terms/magnetic_force_term.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace magbrush;
using namespace magbrush::magnetics;

namespace {

struct Outcome
{
  std::vector<double> x, y, z, vx, vy, vz; // by particle id
  double seconds = 0.0;
  long evaluations = 0;
};

Outcome run(const Case &c, double refresh, double staleness, long steps)
{
  dem::DemSystem system(c);
  system.insert_particles();
  system.initialize();
  MagneticSettings s = MagneticSettings::from_case(c.dem);
  s.refresh_interval = refresh;
  s.staleness_fraction = staleness;
  auto term = std::make_unique<MagneticForceTerm>(
    c, s, AppliedMagneticField::uniform(c.applied_field.uniform_direction, c.applied_field.uniform_magnitude),
    system.box().length);
  MagneticForceTerm *magnetic = term.get();
  system.add_force_term(std::move(term));
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k)
    system.step();
  Outcome o;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.evaluations = magnetic->evaluations();
  const auto &p = system.particles();
  const std::size_t n = p.size();
  for (auto *v : {&o.x, &o.y, &o.z, &o.vx, &o.vy, &o.vz})
    v->assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::size_t id = static_cast<std::size_t>(p.id[k]);
    o.x[id] = p.x[k]; o.y[id] = p.y[k]; o.z[id] = p.z[k];
    o.vx[id] = p.vx[k]; o.vy[id] = p.vy[k]; o.vz[id] = p.vz[k];
  }
  return o;
}

} // namespace

int main(int argc, char **argv)
{
  const long particles = argc > 1 ? std::atol(argv[1]) : 300;
  const long steps = argc > 2 ? std::atol(argv[2]) : 1000;
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml",
                           {"populations.carrier.count=" + std::to_string(particles),
                            "applied_field.ramp_time=0 s", "dem.settle_time=0 s"});
  std::printf("# Magnetic refresh interval: Kawamoto compression scene, %ld carriers, %ld steps of "
              "%.3g s, field %.0f mT on at once, cutoff %.1f d, model %s\n",
              particles, steps, c.dem.time_step, c.applied_field.uniform_magnitude * 1e3,
              c.dem.magnetic_cutoff, c.dem.magnetic_model.c_str());
  const Outcome ref = run(c, 0.0, std::numeric_limits<double>::infinity(), steps);
  double vscale = 0.0;
  for (std::size_t k = 0; k < ref.x.size(); ++k)
    vscale += ref.vx[k] * ref.vx[k] + ref.vy[k] * ref.vy[k] + ref.vz[k] * ref.vz[k];
  vscale = std::sqrt(vscale / ref.x.size());
  std::printf("reference (every step): %ld evaluations, %.3f s per step, RMS speed %.3e m/s\n",
              ref.evaluations, ref.seconds / steps, vscale);
  std::printf("| refresh [s] | staleness [r] | evaluations | time/step [s] | RMS position diff [m] | RMS velocity diff / RMS speed |\n"
              "|---|---|---|---|---|---|\n");
  const double dt = c.dem.time_step;
  for (double staleness : {std::numeric_limits<double>::infinity(), 0.05})
    for (double interval : {5 * dt, 25 * dt, 100 * dt, 250 * dt})
    {
      const Outcome o = run(c, interval, staleness, steps);
      double dx2 = 0.0, dv2 = 0.0;
      for (std::size_t k = 0; k < ref.x.size(); ++k)
      {
        dx2 += std::pow(o.x[k] - ref.x[k], 2) + std::pow(o.y[k] - ref.y[k], 2) + std::pow(o.z[k] - ref.z[k], 2);
        dv2 += std::pow(o.vx[k] - ref.vx[k], 2) + std::pow(o.vy[k] - ref.vy[k], 2) + std::pow(o.vz[k] - ref.vz[k], 2);
      }
      std::printf("| %.2e | %s | %ld | %.3e | %.3e | %.3e |\n", interval,
                  std::isinf(staleness) ? "off" : "0.05", o.evaluations, o.seconds / steps,
                  std::sqrt(dx2 / ref.x.size()), std::sqrt(dv2 / ref.x.size()) / vscale);
      std::fflush(stdout);
    }
  return 0;
}
