// Field solver benchmarks: error against cost (unknowns, wall time on one core) for element
// degrees 1–3 and mesh levels, for the roller (B on the sleeve vs the exact multipole ring)
// and the nip (E across the gap of two cylinders vs the bipolar solution); and the time from a
// pole-angle change to a new stored field. Prints tables, asserts nothing, exits 0.
#include "field_solver/field_app.h"
#include "field_solver/layered_meshes.h"
#include "fields/multipole_ring.h"
#include "field_solver/potential_problem.h"
#include "field_solver/roller_magnetostatics.h"
#include "tests/field_solver/five_pole_roller.h"
#include "tests/test_temp_dir.h"

#include <deal.II/base/mpi.h>
#include <deal.II/distributed/shared_tria.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>

using namespace magbrush;
using namespace magbrush::field;
using magbrush::field::testing::five_pole_roller;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double eps0 = 8.8541878128e-12;

double now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
    .count();
}

void roller_table()
{
  const Roller roller = five_pole_roller();
  Sleeve sleeve;
  sleeve.radius = 10e-3;
  const MultipoleRing ring(roller);
  std::vector<double> angles, Bn, Bt;
  for (int k = 0; k < 720; ++k)
    angles.push_back(2.0 * pi * k / 720);
  ring.profile(sleeve.radius, angles, Bn, Bt);
  double peak = 0.0;
  for (std::size_t k = 0; k < Bn.size(); ++k)
    peak = std::max(peak, std::hypot(Bn[k], Bt[k]));

  std::printf("\nRoller (five poles, iron shaft): max |dB| on the sleeve / peak |B| vs the exact "
              "multipole ring\n");
  std::printf("  solver  degree  cells_around  cells     unknowns   its  solve+setup_s  "
              "rel_max_error\n");
  using LS = PotentialProblemDescription::LinearSolver;
  for (const LS solver_kind : {LS::direct, LS::cg_amg})
  for (unsigned int degree = 1; degree <= 3; ++degree)
    for (unsigned int n : {32u, 64u, 128u, 256u, 384u})
    {
      if (degree == 1 && n < 64)
        continue;
      if (degree == 3 && n > 256)
        continue;
      if (degree == 2 && n < 64)
        continue;
      if (solver_kind == LS::cg_amg && (degree != 2 || n > 256))
        continue;
      RollerDiscretisation disc;
      disc.degree = degree;
      disc.n_angular = n;
      disc.linear_solver = solver_kind;
      const double t0 = now();
      RollerMagnetostatics solver(MPI_COMM_WORLD, RollerGeometry::from(roller, sleeve),
                                  gaussian_pole_magnetisation(roller.poles), disc);
      solver.run();
      const double seconds = now() - t0;
      std::vector<Vec2> points;
      for (const double a : angles)
        points.push_back({{sleeve.radius * std::cos(a), sleeve.radius * std::sin(a)}});
      const auto B = solver.flux_density(points);
      double err = 0.0;
      for (std::size_t k = 0; k < B.size(); ++k)
      {
        const double c = std::cos(angles[k]), s = std::sin(angles[k]);
        const double bn = B[k][0] * c + B[k][1] * s, bt = -B[k][0] * s + B[k][1] * c;
        err = std::max(err, std::hypot(bn - Bn[k], bt - Bt[k]));
      }
      const auto &r = solver.problem().report();
      std::printf("  %6s  %6u  %12u  %8u  %9llu  %4u  %13.3f  %13.3e\n",
                  solver_kind == LS::direct ? "direct" : "cg_amg", degree, n, r.n_cells,
                  static_cast<unsigned long long>(r.n_dofs), r.iterations, seconds,
                  err / peak);
      std::fflush(stdout);
    }
}

void nip_table()
{
  const double R_drum = 50e-3, R_sleeve = 12.5e-3, gap = 400e-6, V = -600.0;
  const auto g = BipolarGeometry::from_cylinders(R_drum, R_sleeve, gap, 0.05);
  const double dtau = g.tau_right - g.tau_left;
  auto exact_E = [&](double x, double y) {
    const std::complex<double> z(x, y), a(g.focus, 0.0);
    const std::complex<double> dw = 1.0 / (z + a) - 1.0 / (z - a);
    return Vec2{{-V / dtau * dw.real(), V / dtau * dw.imag()}};
  };
  const double x_drum = -g.center_left + R_drum, x_sleeve = g.center_right - R_sleeve;
  std::vector<Point<2>> points;
  for (int i = 1; i < 40; ++i)
    points.emplace_back(x_drum + (x_sleeve - x_drum) * i / 40.0, 0.0);
  const double E_gap = std::abs(exact_E(0.5 * (x_drum + x_sleeve), 0.0)[0]);

  std::printf("\nNip (two cylinders, 400 um gap): max |dE| across the gap / E_gap vs the "
              "bipolar exact solution\n");
  std::printf("  degree  level  cells     unknowns   its  solve+setup_s  rel_max_error  (direct solver)\n");
  for (unsigned int degree = 1; degree <= 3; ++degree)
    for (unsigned int level = 0; level < 4; ++level)
    {
      const double t0 = now();
      dealii::parallel::shared::Triangulation<2> tria(MPI_COMM_WORLD);
      make_bipolar_two_cylinders(tria, g, 4, 32);
      tria.refine_global(level);
      PotentialProblemDescription d;
      d.degree = degree;
      d.linear_solver = PotentialProblemDescription::LinearSolver::direct;
      d.coefficient[0] = eps0;
      auto exact_phi = [&](const Point<2> &p) {
        return V * (g.to_bipolar(p[0], p[1])[0] - g.tau_left) / dtau;
      };
      d.dirichlet[0] = [](const Point<2> &) { return 0.0; };
      d.dirichlet[1] = [V](const Point<2> &) { return V; };
      d.dirichlet[2] = exact_phi;
      d.dirichlet[3] = exact_phi;
      PotentialProblem problem(tria, d);
      problem.run();
      const double seconds = now() - t0;
      const auto grad = problem.gradients_at(points);
      double err = 0.0;
      for (std::size_t k = 0; k < points.size(); ++k)
      {
        const Vec2 e = exact_E(points[k][0], points[k][1]);
        err = std::max(err, std::hypot(-grad[k][0] - e[0], -grad[k][1] - e[1]));
      }
      const auto &r = problem.report();
      std::printf("  %6u  %5u  %8u  %9llu  %4u  %13.3f  %13.3e\n", degree, level, r.n_cells,
                  static_cast<unsigned long long>(r.n_dofs), r.iterations, seconds,
                  err / E_gap);
      std::fflush(stdout);
    }
}

// The production path at the case defaults: change one pole angle, store the new field.
void pole_change_timing()
{
  Case c;
  c.name = "bench_pole_change";
  c.roller = five_pole_roller();
  c.sleeve = Sleeve{};
  c.sleeve->radius = 10e-3;
  c.sleeve->thickness = 0.5e-3;
  c.field.output_dir = magbrush::testing::test_temp_dir("field_bench").string();
  FieldRunOptions options;
  options.vtu = false;
  options.electric = false;

  std::printf("\nPole-angle change to a new stored field (case defaults: FE_Q(%d), sleeve "
              "mesh size %.0f um; one core)\n",
              c.field.element_degree, c.field.mesh_size_sleeve * 1e6);
  double t0 = now();
  compute_magnetic_field(c, options, MPI_COMM_WORLD);
  std::printf("  first solve                      %6.2f s\n", now() - t0);
  c.roller->poles[1].angle += 2.0 * pi / 180.0;
  t0 = now();
  compute_magnetic_field(c, options, MPI_COMM_WORLD);
  std::printf("  N1 moved by 2 deg: new field     %6.2f s\n", now() - t0);
  t0 = now();
  compute_magnetic_field(c, options, MPI_COMM_WORLD);
  std::printf("  unchanged case: up to date       %6.3f s\n", now() - t0);
  std::filesystem::remove_all(c.field.output_dir);
}

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
  {
    roller_table();
    nip_table();
    pole_change_timing();
  }
  catch (const std::exception &e)
  {
    std::printf("bench_field: %s\n", e.what());
  }
  return 0;
}
