// Mesh cost against geometric accuracy: for each element size, the cells, the time to mesh and
// write, the worst relative region-area error against the exact areas and the worst cell
// quality. Prints tables; asserts nothing.
#include "geometry/mesh_nip.h"
#include "geometry/mesh_roller.h"
#include "tests/geometry/mesh_test_cases.h"

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace magbrush;

namespace {
template <class F>
void row(const char *label, double size, F &&write)
{
  const auto t0 = std::chrono::steady_clock::now();
  const MeshSummary s = write();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double worst = 0.0;
  for (const auto &r : s.regions)
    worst = std::max(worst, std::abs(r.area / r.exact_area - 1.0));
  std::printf("%-8s %10.3f %9zu %9zu %9.2f %14.2e %10.3f\n", label, size * 1e3, s.n_quads, s.n_nodes, seconds, worst,
              s.min_quality);
}
} // namespace

int main()
{
  const std::string dir = magbrush::testing::scratch_dir("bench_meshes");
  std::printf("mesh     size [mm]     quads     nodes  time [s]  max |area err|  min qual\n");
  for (double h : {0.8e-3, 0.4e-3, 0.2e-3, 0.1e-3})
  {
    Case c = magbrush::testing::coarse_roller_case();
    c.field.mesh_size_sleeve = h;
    c.field.mesh_size_far = std::max(2e-3, 5 * h);
    row("roller", h, [&] { return write_roller_mesh(c, dir + "/roller.msh"); });
  }
  for (double h : {80e-6, 40e-6, 20e-6, 10e-6})
  {
    Case c = magbrush::testing::coarse_nip_case(20e-6);
    c.field.mesh_size_gap = h;
    c.field.mesh_size_far = 2e-3;
    row("nip", h, [&] { return write_nip_mesh(c, dir + "/nip.msh"); });
  }
  return 0;
}
