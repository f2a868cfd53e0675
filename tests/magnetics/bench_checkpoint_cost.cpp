// What a checkpoint costs with the magnetics on: its size per carrier, the time to write it
// (CRC-32 included), to verify its checksum, and to read it back (checksum, then the state and
// the far-field cells built again), for brushes of growing size — against the run's first
// (cold) magnetic evaluation, which a restart without the magnetic state would repeat, and one
// step, so that the checkpoint interval can be judged.
//
//   bench_checkpoint_cost [carriers ...]     (default 500 2000 8000)
#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/magnetic_force_term.h"

#include "case/case_parser.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

using namespace magbrush;

namespace {

// `n` carriers of 60 µm in a periodic slab of side L (about 0.25 solid fraction over 0.5 mm).
std::string brush_case(long n)
{
  const double side_mm = std::sqrt(static_cast<double>(n) / 700.0);
  char text[2048];
  std::snprintf(text, sizeof text, R"(
name: checkpoint_cost
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, mu_r: 3.9, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 60 um, count: %ld, insert_box: [[0 mm, 0 mm, 0.03 mm], [%.4f mm, %.4f mm, 0.6 mm]]}
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
applied_field: {kind: uniform, direction: [0, 0, 1], magnitude: 130 mT}
dem: {time_step: 2e-8 s, periodic_length_x: %.4f mm, periodic_length_y: %.4f mm, magnetic_refresh: 5 us}
)",
                n, side_mm, side_mm, side_mm, side_mm);
  return text;
}

} // namespace

int main(int argc, char **argv)
{
  std::vector<long> sizes;
  for (int k = 1; k < argc; ++k)
    sizes.push_back(std::atol(argv[k]));
  if (sizes.empty())
    sizes = {500, 2000, 8000};
  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("magbrush_bench_checkpoint_" + std::to_string(getpid())))
                            .string();
  std::filesystem::create_directories(dir);
  std::printf("checkpoint cost with the magnetics on (defaults: cell-multipole far field, relative mode), %d threads\n",
              omp_get_max_threads());
  std::printf("%9s %12s %12s %10s %10s %10s %12s %10s\n", "carriers", "bytes", "bytes/bead", "write [s]",
              "verify [s]", "read [s]", "first eval [s]", "step [s]");
  for (const long n : sizes)
  {
    const Case c = parse_case_text(brush_case(n), "checkpoint_cost.yaml");
    dem::DemSystem system(c);
    dem::add_case_force_terms(system, c);
    system.insert_particles();
    system.initialize(); // (the first, cold, full evaluation)
    const auto *magnetics = [&]() -> const magnetics::MagneticForceTerm * {
      for (const auto &t : system.force_terms())
        if (auto *m = dynamic_cast<const magnetics::MagneticForceTerm *>(t.get()))
          return m;
      return nullptr;
    }();
    const double t_steps = omp_get_wtime();
    const int steps = 20;
    system.advance(steps);
    const double step_s = (omp_get_wtime() - t_steps) / steps;
    const std::string path = dir + "/checkpoint.bin";
    double t0 = omp_get_wtime();
    system.write_checkpoint(path);
    const double write_s = omp_get_wtime() - t0;
    t0 = omp_get_wtime();
    { dem::CheckpointReader verify(path); }
    const double verify_s = omp_get_wtime() - t0;
    dem::DemSystem restored(c);
    dem::add_case_force_terms(restored, c);
    t0 = omp_get_wtime();
    restored.read_checkpoint(path);
    const double read_s = omp_get_wtime() - t0;
    const auto bytes = std::filesystem::file_size(path);
    const double full_s = magnetics->refresh_counts().cold_s;
    std::printf("%9zu %12ju %12.0f %10.4f %10.4f %10.4f %12.4f %10.5f\n", system.particles().size(),
                static_cast<std::uintmax_t>(bytes), static_cast<double>(bytes) / static_cast<double>(n), write_s,
                verify_s, read_s, full_s, step_s);
  }
  std::filesystem::remove_all(dir);
  return 0;
}
