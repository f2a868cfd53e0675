// The magnet roller's field: the A_z problem (Kweon eq. 9–10) on a concentric layered mesh
// (shaft, magnet, air with the sleeve surface and probe circles as mesh lines, open-boundary
// shell), solved by PotentialProblem. B = curl(A ẑ) = (∂A/∂y, −∂A/∂x) by exact differentiation
// of the FE solution.
//
// The roller is rotationally layered, so the production mesh is built here with deal.II
// (layered_meshes.h) rather than read from Gmsh: every circle is exact at every refinement
// level, which is what makes the sleeve profile converge at the full order O(h^p).
//
// A soft-magnetic blade (μr > 1) breaks the rotational symmetry: for such a case the solver
// reads the Gmsh roller mesh of geometry/ instead (RollerMeshFile, write_roller_mesh_file):
// regions by mesh_tags.h, straight faces curved onto the circles of roller_mesh_circles() by a
// SphericalManifold per circle.
#pragma once

#include "case/case_model.h"
#include "geometry/mesh_common.h"
#include "field_solver/potential_problem.h"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace magbrush::field {

// Region (material) ids of the roller mesh.
namespace roller_region {
constexpr MaterialId shaft = 1, magnet = 2, air = 3, shell = 4;
}

struct RollerGeometry
{
  double shaft_radius = 0.0;  // 0: the magnet fills the disk
  double shaft_mu_r = 1.0;
  double magnet_radius = 0.0;
  double magnet_mu_r = 1.0;
  double sleeve_radius = 0.0; // outer sleeve surface (non-magnetic)

  static RollerGeometry from(const Roller &roller, const Sleeve &sleeve);
};

struct RollerDiscretisation
{
  unsigned int degree = 2;
  unsigned int n_angular = 64;           // coarse cells around (multiple of 4)
  unsigned int refinements = 0;          // global refinements of the coarse mesh
  double outer_radius_factor = 2.0;      // shell from R1 = factor × sleeve radius ...
  double shell_ratio = 2.0;              // ... to R2 = shell_ratio × R1
  std::vector<double> extra_circles;     // further mesh circles (probe, grid edge) [m]
  double solver_tolerance = 1e-12;
  PotentialProblemDescription::LinearSolver linear_solver =
    PotentialProblemDescription::LinearSolver::cg_amg;
  LinearAlgebraBackend linear_algebra = LA; // the configured backend (linear_algebra.h)
};

// The Gmsh roller mesh (geometry/mesh_roller.h) and what the solver needs to know about it.
// Regions are mesh_tags (shaft 1, magnet 2, sleeve wall 3, air 4, shell 5, blade 20 + i),
// A = 0 on mesh_tags::outer_boundary.
struct RollerMeshFile
{
  std::string path;                 // MSH 2.2
  std::vector<MeshCircle> circles;  // every curved mesh line (roller_mesh_circles)
  OpenBoundaryShell shell;          // the shell-transformed annulus (roller_shell)
  std::vector<double> blade_mu_r;   // μr of Case::blades[i] (region blade_base + i)
};

// Writes the case's roller mesh to `msh_path` (on rank 0; all ranks return after it is
// written). Cells are `degree` × field.mesh_size_sleeve at the sleeve, the rule of the layered
// mesh (p nodes per element edge).
RollerMeshFile write_roller_mesh_file(const Case &c, const std::string &msh_path,
                                      unsigned int degree, MPI_Comm communicator);

// Magnetisation M(x, y) [A/m] inside the magnet.
using Magnetisation = std::function<Vec2(double x, double y)>;

// M = r̂ Σ_i M_i exp(−α_i wrap(θ − φ_i)²).
Magnetisation gaussian_pole_magnetisation(const std::vector<Pole> &poles);

class RollerMagnetostatics
{
public:
  RollerMagnetostatics(MPI_Comm communicator, const RollerGeometry &geometry,
                       Magnetisation magnetisation, const RollerDiscretisation &discretisation);
  // On the Gmsh mesh (discretisation.n_angular, extra_circles and the shell factors unused).
  RollerMagnetostatics(MPI_Comm communicator, const RollerGeometry &geometry,
                       Magnetisation magnetisation, const RollerDiscretisation &discretisation,
                       RollerMeshFile mesh_file);
  ~RollerMagnetostatics();

  void run(); // make_mesh → PotentialProblem::run

  // B [T] at points (collective; all ranks pass and receive the same).
  std::vector<Vec2> flux_density(const std::vector<Vec2> &points) const;
  std::vector<double> vector_potential(const std::vector<Vec2> &points) const;

  // The gaussmeter's view on a circle: B_n = B·r̂ (outward), B_t = B·θ̂ (counter-clockwise).
  struct Profile
  {
    std::vector<double> angle, Bn, Bt; // [rad], [T], [T]
  };
  Profile profile(double radius, unsigned int n_angles) const;

  void write_vtu(const std::string &directory, const std::string &basename) const;

  const PotentialProblem &problem() const { return *potential; }
  const RollerGeometry &geometry() const { return roller; }
  double shell_inner_radius() const;

private:
  void make_mesh();
  void read_mesh_file();
  PotentialProblemDescription describe() const;

  MPI_Comm communicator;
  RollerGeometry roller;
  Magnetisation magnetisation;
  RollerDiscretisation discretisation;
  std::optional<RollerMeshFile> mesh_file;
  dealii::parallel::shared::Triangulation<2> triangulation;
  std::unique_ptr<PotentialProblem> potential;
};

} // namespace magbrush::field
