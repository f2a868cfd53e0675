// The magnetic share of the DEM step time on the paper scenes, measured side by side in one
// run: the same system stepped without magnetics (contact-only), then with the magnetics at
// the case defaults (cell-multipole far field, refresh 5 µs = 250 steps, staleness 5 % of a
// radius), then with the previous default (hard cutoff 12 d). The scenes are the cases as
// inserted (loose packing, before settling); the applied field is uniform (the nip's roller
// grid needs the field solver; the grid lookup is a small part of a refresh).
//
//   bench_magnetic_step_share [nip_carriers] [compression_carriers] [steps]
#include "dem_system.h"
#include "magnetic_force_term.h"

#include "applied_magnetic_field.h"
#include "case_parser.h"

#include <omp.h>

#include <cstdio>
#include <cstdlib>
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

void scene(const char *label, const std::string &file, long carriers, long steps,
           const Vec3 &direction, double magnitude)
{
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/" + file,
                           {"populations.carrier.count=" + std::to_string(carriers),
                            "dem.settle_time=0 s"});
  std::printf("\n%s: %ld carriers, %ld steps of %.3g s per phase, refresh %.3g s, %d threads\n\n",
              label, carriers, steps, c.dem.time_step, c.dem.magnetic_refresh, omp_get_max_threads());
  std::printf("| phase | s/step | magnetic share (vs contact-only) | evaluations | s/evaluation | sweeps | far passes | last evaluation: lists / tensors / far / sweeps / forces [s] |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  dem::DemSystem system(c);
  system.insert_particles();
  system.initialize();
  time_steps(system, 20); // first neighbour lists, caches
  const double contact = time_steps(system, steps);
  std::printf("| contact only | %.3e | — | 0 | — | — | — | — |\n", contact);
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
    const double with = time_steps(system, steps);
    const long evaluations = term->evaluations() - before;
    const double contact_now = contact; // measured above, same system
    const MagneticStats &st = term->last_stats();
    std::printf("| %s | %.3e | %+.0f %% | %ld | %.3f (cold %.3f) | %d | %d | %.3f / %.3f / %.3f / %.3f / %.3f |\n",
                name, with, 100.0 * (with - contact_now) / contact_now, evaluations,
                evaluations ? (with - contact_now) * steps / evaluations : 0.0, cold, st.sweeps,
                st.far_passes, st.time_lists, st.time_tensors, st.time_far, st.time_sweeps,
                st.time_forces);
    std::fflush(stdout);
    return term;
  };
  MagneticSettings defaults = MagneticSettings::from_case(c.dem);
  MagneticForceTerm *term = add("magnetics, defaults (cell_multipole)", defaults);
  term->set_enabled(false);
  MagneticSettings old = defaults;
  old.far_field = FarField::none;
  old.cutoff_diameters = 12.0;
  add("magnetics, hard cutoff 12 d (old default)", old);
}

} // namespace

int main(int argc, char **argv)
{
  const long nip = argc > 1 ? std::atol(argv[1]) : 12300;
  const long compression = argc > 2 ? std::atol(argv[2]) : 4420;
  const long steps = argc > 3 ? std::atol(argv[3]) : 500;
  scene("Nip (cases/kawamoto_nip.yaml), uniform 0.1 T along x", "kawamoto_nip.yaml", nip, steps,
        {1.0, 0.0, 0.0}, 0.1);
  scene("Compression (cases/kawamoto_brush_compression.yaml), 130 mT along z",
        "kawamoto_brush_compression.yaml", compression, steps, {0.0, 0.0, 1.0}, 0.13);
  return 0;
}
