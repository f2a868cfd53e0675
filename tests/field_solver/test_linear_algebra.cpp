// The two linear-algebra backends (field_solver/linear_algebra.h) give the same fields. A build
// solves with the backend it was configured with; both are compiled in, so this test solves
// the field stage's problems of the default cases in each (PotentialProblemDescription::
// linear_algebra) and compares what the stage stores: A_z on the polar grid and B on the
// sleeve (the magnet roller of both cases), Φ on the window over the nip (the bias alone and
// the image alone at phase 0, Kweon's development cell). With both solvers the stage uses:
// MUMPS (one process), which leaves only round-off between the backends, and CG + AMG (in
// parallel; here serially), where BoomerAMG and ML stop at different iterates within the
// tolerance of 1e-12 of the right-hand side. The bound is 1e-10 of each field's peak.
#include "tests/field_solver/mpi_environment.h"

#include "case/case_parser.h"
#include "fields/field_grid.h"
#include "field_solver/field_app.h"
#include "field_solver/nip_electrostatics.h"
#include "field_solver/roller_magnetostatics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace magbrush::field {
namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double bound = 1e-10; // of the peak

using Backend = LinearAlgebraBackend;
using LinearSolver = PotentialProblemDescription::LinearSolver;

Case default_case(const std::string &name)
{
  return load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/" + name + ".yaml", {});
}

// max |a − b| / max |a| over the samples of one field (scalar or the magnitude of a vector).
template <class T>
double relative_difference(const std::vector<T> &a, const std::vector<T> &b)
{
  const auto magnitude = [](const T &v) {
    if constexpr (std::is_same_v<T, double>)
      return std::abs(v);
    else
      return std::hypot(v[0], v[1]);
  };
  double diff = 0.0, peak = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
  {
    T d = a[k];
    if constexpr (std::is_same_v<T, double>)
      d -= b[k];
    else
      d = {{a[k][0] - b[k][0], a[k][1] - b[k][1]}};
    diff = std::max(diff, magnitude(d));
    peak = std::max(peak, magnitude(a[k]));
  }
  EXPECT_GT(peak, 0.0);
  return diff / peak;
}

struct RollerField
{
  std::vector<double> A_z; // on the stored polar grid's nodes
  std::vector<Vec2> B;     // on the sleeve, every degree
  SolveReport report;
};

const char *solver_name(LinearSolver solver)
{
  return solver == LinearSolver::direct ? "direct" : "CG + AMG";
}

// The magnetic field as `magbrush field` solves it, in `backend` with `solver`.
RollerField solve_roller(const Case &c, Backend backend, LinearSolver solver)
{
  RollerDiscretisation disc = roller_discretisation(c);
  disc.linear_solver = solver;
  disc.linear_algebra = backend;
  RollerMagnetostatics roller(MPI_COMM_WORLD, RollerGeometry::from(*c.roller, *c.sleeve),
                              gaussian_pole_magnetisation(c.roller->poles), disc);
  roller.run();
  const PolarGridLayout layout = polar_grid_layout(c);
  PolarGrid grid;
  grid.r_min = layout.r_min;
  grid.r_max = layout.r_max;
  grid.n_r = layout.n_r;
  grid.n_theta = layout.n_theta;
  std::vector<Vec2> nodes, sleeve;
  for (int i = 0; i < grid.n_r; ++i)
    for (int j = 0; j < grid.n_theta; ++j)
      nodes.push_back({{grid.r(i) * std::cos(grid.theta(j)), grid.r(i) * std::sin(grid.theta(j))}});
  for (int k = 0; k < 360; ++k)
    sleeve.push_back({{c.sleeve->radius * std::cos(k * pi / 180.0),
                       c.sleeve->radius * std::sin(k * pi / 180.0)}});
  return {roller.vector_potential(nodes), roller.flux_density(sleeve), roller.problem().report()};
}

void expect_roller_fields_agree(const std::string &case_name)
{
  const Case c = default_case(case_name);
  for (const LinearSolver solver : {LinearSolver::direct, LinearSolver::cg_amg})
  {
    const RollerField petsc = solve_roller(c, Backend::petsc, solver);
    const RollerField trilinos = solve_roller(c, Backend::trilinos, solver);
    EXPECT_EQ(petsc.report.linear_algebra, Backend::petsc);
    EXPECT_EQ(trilinos.report.linear_algebra, Backend::trilinos);
    const double dA = relative_difference(petsc.A_z, trilinos.A_z);
    const double dB = relative_difference(petsc.B, trilinos.B);
    std::printf("%s magnetic, %s (%llu unknowns): max |dA_z|/peak %.2e, max |dB|/peak on the "
                "sleeve %.2e; PETSc %u iterations %.2f s, Trilinos %u iterations %.2f s\n",
                case_name.c_str(), solver_name(solver),
                static_cast<unsigned long long>(petsc.report.n_dofs), dA, dB,
                petsc.report.iterations, petsc.report.solve_seconds, trilinos.report.iterations,
                trilinos.report.solve_seconds);
    EXPECT_LE(dA, bound) << solver_name(solver);
    EXPECT_LE(dB, bound) << solver_name(solver);
  }
}

TEST(LinearAlgebraBackends, GiveTheSameRollerFieldOnTheDefaultNip)
{
  expect_roller_fields_agree("kawamoto_nip_fed");
}

TEST(LinearAlgebraBackends, GiveTheSameRollerFieldOnTheDevelopmentCell)
{
  expect_roller_fields_agree("kweon_development");
}

// Φ on the stored window over the nip (field_app.cpp), bias alone and image alone.
TEST(LinearAlgebraBackends, GiveTheSameNipFieldOnTheDevelopmentCell)
{
  // The case's 1 mm lines rather than its solid area: an image that varies along the drum.
  Case c = default_case("kweon_development");
  c.electric.image.period = 2e-3;
  c.electric.image.duty = 0.5;
  ASSERT_TRUE(c.electric.enabled);
  const NipLayout layout = NipLayout::from(c.sleeve->radius, c.drum.radius, c.drum.gap,
                                           c.drum.angle, c.drum.pc_thickness);
  const double half = 2e-3 + c.drum.gap;
  const double rc = c.sleeve->radius + 0.5 * c.drum.gap;
  const double xc = rc * std::cos(c.drum.angle), yc = rc * std::sin(c.drum.angle);
  const int n = 1 + static_cast<int>(std::ceil(2.0 * half / c.field.grid_electric_spacing - 1e-9));
  std::vector<Vec2> nodes;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      nodes.push_back({{xc - half + 2.0 * half * i / (n - 1), yc - half + 2.0 * half * j / (n - 1)}});
  LatentImage no_image = c.electric.image;
  no_image.dark_value = no_image.light_value = 0.0;

  const auto solve = [&](Backend backend, LinearSolver solver, double bias,
                         const LatentImage &image) {
    NipDiscretisation disc = nip_discretisation(c, layout);
    disc.linear_solver = solver;
    disc.linear_algebra = backend;
    NipElectrostatics nip(MPI_COMM_WORLD, layout, c.drum.pc_eps_r, bias, image, disc);
    nip.run();
    return nip.air_potential(nodes);
  };
  for (const LinearSolver solver : {LinearSolver::direct, LinearSolver::cg_amg})
  {
    const double d_bias =
      relative_difference(solve(Backend::petsc, solver, c.electric.bias, no_image),
                          solve(Backend::trilinos, solver, c.electric.bias, no_image));
    const double d_image =
      relative_difference(solve(Backend::petsc, solver, 0.0, c.electric.image),
                          solve(Backend::trilinos, solver, 0.0, c.electric.image));
    std::printf("kweon_development electric, %s: max |dPhi|/peak bias %.2e, image %.2e\n",
                solver_name(solver), d_bias, d_image);
    EXPECT_LE(d_bias, bound) << solver_name(solver);
    EXPECT_LE(d_image, bound) << solver_name(solver);
  }
}

} // namespace
} // namespace magbrush::field
