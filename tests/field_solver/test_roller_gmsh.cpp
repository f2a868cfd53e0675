// The roller field on the Gmsh roller mesh of geometry/ (the path taken when a blade is
// soft-magnetic): the mesh is read with GridIn, its circles curved by manifolds, its regions
// mapped to μr by mesh_tags.h.
//
//  (a) Exact: with the blade at μr = 1 the field is the multipole ring's (coupling/
//      multipole_ring.h); the Gmsh path must meet it about as well as the layered path at the
//      same sleeve element size.
//  (b) Plausibility only, not an exact solution (no closed form for a plate next to a
//      multipole roller): a μr = 100 blade concentrates the flux (|B| inside it > 1.5 × the
//      μr = 1 value), B_n is continuous across its side (5 %; B = curl A is divergence-free in
//      each cell and A is continuous), H_t = B_t/μ is continuous only weakly (within 50 %
//      20 µm either side: B_t jumps by about μr), and the field on the sleeve on the far side
//      of the roller (45°–135°, the blade is at 270°) changes by less than 1 % of its peak.
#include "tests/field_solver/convergence.h"
#include "tests/field_solver/mpi_environment.h"

#include "fields/multipole_ring.h"
#include "field_solver/roller_magnetostatics.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <unistd.h>

using namespace magbrush;
using namespace magbrush::field;
using namespace magbrush::field::testing;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr unsigned int degree = 3;
constexpr double mesh_size = 0.25e-3; // field.mesh_size_sleeve: cells p × 0.25 mm at the sleeve

// The 5-pole roller (iron shaft) with a 1.5 mm × 6 mm doctor blade below it, 0.5 mm gap.
Case roller_case(double blade_mu_r)
{
  Case c;
  c.name = "field_gmsh_roller";
  Roller r;
  r.shaft_radius = 3e-3;
  r.shaft_mu_r = 1000;
  r.magnet_radius = 9.3e-3;
  for (int k = 0; k < 5; ++k)
    r.poles.push_back({"P" + std::to_string(k), 2 * pi * k / 5, (k % 2 ? 1 : -1) * 2e5, 10.0});
  c.roller = r;
  Sleeve s;
  s.radius = 10e-3;
  s.thickness = 0.5e-3;
  c.sleeve = s;
  BladeOrGuide blade;
  blade.name = "doctor";
  blade.mu_r = blade_mu_r;
  blade.is_doctor_blade = true;
  blade.gap = 0.5e-3;
  blade.polygon = {Vec2{{-0.75e-3, -10.5e-3}}, Vec2{{0.75e-3, -10.5e-3}},
                   Vec2{{0.75e-3, -16.5e-3}}, Vec2{{-0.75e-3, -16.5e-3}}};
  c.blades.push_back(blade);
  c.field.mesh_size_sleeve = mesh_size;
  c.field.mesh_size_far = 3e-3;
  c.field.element_degree = degree;
  return c;
}

RollerDiscretisation discretisation()
{
  RollerDiscretisation d;
  d.degree = degree;
  d.n_angular = 4 * static_cast<unsigned int>(std::ceil(2 * pi * 10e-3 / (degree * mesh_size) / 4));
  d.linear_solver = PotentialProblemDescription::LinearSolver::direct;
  return d;
}

double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One mesh for both tests (the blade region is meshed because its μr is 100 when written);
// the solver is given the blade's μr separately.
const RollerMeshFile &mesh_file()
{
  static const RollerMeshFile file = [] {
    const auto dir = magbrush::testing::test_temp_dir("field_gmsh");
    return write_roller_mesh_file(roller_case(100.0), (dir / "roller.msh").string(), degree,
                                  MPI_COMM_WORLD);
  }();
  return file;
}

std::unique_ptr<RollerMagnetostatics> solve_on_gmsh(double blade_mu_r)
{
  const Case c = roller_case(blade_mu_r);
  RollerMeshFile file = mesh_file();
  file.blade_mu_r = {blade_mu_r};
  const auto t0 = std::chrono::steady_clock::now();
  auto solver = std::make_unique<RollerMagnetostatics>(
    MPI_COMM_WORLD, RollerGeometry::from(*c.roller, *c.sleeve),
    gaussian_pole_magnetisation(c.roller->poles), discretisation(), file);
  solver->run();
  std::printf("Gmsh mesh, blade mu_r = %g: %u cells, %llu unknowns, %.2f s\n", blade_mu_r,
              solver->problem().report().n_cells,
              static_cast<unsigned long long>(solver->problem().report().n_dofs),
              seconds_since(t0));
  return solver;
}

std::vector<Vec2> exact_ring_field(const Roller &roller, const std::vector<Vec2> &points)
{
  const MultipoleRing ring(roller);
  std::vector<Vec2> B;
  for (const auto &p : points)
  {
    const auto f = ring.field(p[0], p[1]);
    B.push_back({{f.Bx, f.By}});
  }
  return B;
}

double magnitude(const Vec2 &v) { return std::hypot(v[0], v[1]); }

} // namespace

TEST(FieldRollerGmsh, NonMagneticBladeMatchesMultipoleRing)
{
  const Case c = roller_case(1.0);
  const auto points = circle_points(c.sleeve->radius, 360, 0.01);
  const auto exact = exact_ring_field(*c.roller, points);

  const auto gmsh = solve_on_gmsh(1.0);
  const double gmsh_error = max_vector_error(gmsh->flux_density(points), exact, max_magnitude(exact));

  const auto t0 = std::chrono::steady_clock::now();
  RollerMagnetostatics layered(MPI_COMM_WORLD, RollerGeometry::from(*c.roller, *c.sleeve),
                               gaussian_pole_magnetisation(c.roller->poles), discretisation());
  layered.run();
  const double layered_error =
    max_vector_error(layered.flux_density(points), exact, max_magnitude(exact));
  std::printf("layered mesh: %u cells, %llu unknowns, %.2f s\n",
              layered.problem().report().n_cells,
              static_cast<unsigned long long>(layered.problem().report().n_dofs),
              seconds_since(t0));
  std::printf("max |dB|/peak on the sleeve vs the exact ring: Gmsh %.2e, layered %.2e\n",
              gmsh_error, layered_error);
  EXPECT_LT(layered_error, 1e-3);
  EXPECT_LT(gmsh_error, 1e-3); // the same bound

  // The circles are curved: every circle of the mesh has faces on its manifold.
  std::vector<unsigned int> curved(mesh_file().circles.size(), 0);
  for (const auto &cell : gmsh->problem().dof_handler().get_triangulation().active_cell_iterators())
    for (const auto f : cell->face_indices())
      if (cell->face(f)->manifold_id() < curved.size())
        ++curved[cell->face(f)->manifold_id()];
  for (std::size_t k = 0; k < curved.size(); ++k)
  {
    std::printf("circle %s (r = %.2f mm): %u curved face sides\n",
                mesh_file().circles[k].name.c_str(), mesh_file().circles[k].radius * 1e3, curved[k]);
    EXPECT_GE(curved[k], 16u) << mesh_file().circles[k].name;
  }
}

TEST(FieldRollerGmsh, SoftMagneticBladePlausibility)
{
  const auto air = solve_on_gmsh(1.0);
  const auto iron = solve_on_gmsh(100.0);

  // Flux concentration: along the blade's axis, inside it, near the sleeve.
  const std::vector<Vec2> inside{{{0.0, -10.8e-3}}, {{0.0, -12.0e-3}}, {{0.0, -13.5e-3}}};
  const auto B_air = air->flux_density(inside), B_iron = iron->flux_density(inside);
  for (std::size_t k = 0; k < inside.size(); ++k)
  {
    std::printf("|B| inside the blade at y = %.1f mm: mu_r 1: %.4f T, mu_r 100: %.4f T\n",
                inside[k][1] * 1e3, magnitude(B_air[k]), magnitude(B_iron[k]));
    EXPECT_GT(magnitude(B_iron[k]), 1.5 * magnitude(B_air[k]));
  }

  // Interface conditions across the blade's side x = 0.75 mm (normal x̂): B_n = B_x is
  // continuous (A is), H_t = B_y/μ about continuous (weakly imposed).
  const double d = 20e-6;
  for (const double y : {-12.0e-3, -13.5e-3})
  {
    const auto B = iron->flux_density({{{0.75e-3 - d, y}}, {{0.75e-3 + d, y}}});
    const double scale = std::max(magnitude(B[0]), magnitude(B[1]));
    std::printf("blade side y = %.1f mm: Bn in %.4f out %.4f; Ht*mu0 in %.5f out %.5f T\n",
                y * 1e3, B[0][0], B[1][0], B[0][1] / 100.0, B[1][1]);
    EXPECT_LT(std::abs(B[0][0] - B[1][0]), 0.05 * scale);
    EXPECT_LT(std::abs(B[0][1] / 100.0 - B[1][1]), 0.5 * std::abs(B[1][1]) + 1e-3 * scale);
  }

  // Far from the blade: the sleeve surface on the opposite side (45° to 135°).
  std::vector<Vec2> far;
  for (int k = 0; k <= 90; ++k)
  {
    const double t = (45.0 + k) * pi / 180.0;
    far.push_back({{10e-3 * std::cos(t), 10e-3 * std::sin(t)}});
  }
  const double change =
    max_vector_error(iron->flux_density(far), air->flux_density(far), max_magnitude(air->flux_density(far)));
  std::printf("far side of the roller (45-135 deg, sleeve): max |dB|/peak = %.2e\n", change);
  EXPECT_LT(change, 1e-2);
}
