// One scalar potential problem in the cross-section plane, the common core of both fields:
//
//     ∫ K ∇u·∇v dx  =  ∫ s·∇v dx  +  ∫_Γσ σ v ds        for all v vanishing on Dirichlet parts,
//
//  * magnetostatics (u = A_z):  K = ν = 1/(μ0 μr),  s = (−M_y, M_x)/μr  (Kweon eq. 9–10), σ = 0;
//  * electrostatics (u = Φ):    K = ε0 εr,          s = 0,  σ = latent-image surface charge on
//    the photoconductor surface (a jump ε ∂Φ/∂n = σ across an interior interface).
//
// The problem is described by material ids (one coefficient per region), a vector source, the
// Dirichlet boundaries, interfaces carrying surface charge, periodic pairs, and optionally one
// shell-transformed region that maps the open exterior onto a finite annulus
// (shell_transformation.h). The mesh comes from outside (layered_meshes.h for verification,
// Gmsh for production) with manifolds attached to every curved boundary and interface.
//
// run() reads like the algorithm (deal.II step-40): setup → assemble → solve → estimate.
// Parallel: the triangulation is a parallel::shared::Triangulation partitioned by METIS; the
// linear system is a matrix of the configured backend (linear_algebra.h: PETSc or Trilinos),
// solved by MUMPS or by CG with algebraic multigrid (linear_system.h). The solution is kept in
// deal.II's own distributed vector, so evaluation and output never depend on the backend.
#pragma once

#include "field_solver/linear_algebra.h"
#include "field_solver/linear_system.h"
#include "field_solver/shell_transformation.h"

#include <deal.II/base/index_set.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/distributed/shared_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/fe/mapping_q_cache.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace magbrush::field {

using dealii::Point;
using dealii::Tensor;
using MaterialId = dealii::types::material_id;
using BoundaryId = dealii::types::boundary_id;

// A shell-transformed region: cells with this material id use K = coefficient · K_shell(x).
struct ShellRegion
{
  MaterialId material = 0;
  double coefficient = 0.0; // ν0 or ε0 of the (air) exterior it stands for
  ShellTransformation transformation;
};

// Surface charge σ(x) on the interface between two regions (faces of `inner` cells whose
// neighbour is an `outer` cell).
struct SurfaceCharge
{
  MaterialId inner = 0;
  MaterialId outer = 0;
  std::function<double(const Point<2> &)> density; // [C/m²]
};

// Two boundaries identified by translation along x (a periodic slab).
struct PeriodicPair
{
  BoundaryId left = 0;
  BoundaryId right = 1;
  int direction = 0;
};

struct PotentialProblemDescription
{
  std::string name = "potential";                  // used in messages and output names
  unsigned int degree = 2;                         // FE_Q(p) and MappingQ(p)
  std::map<MaterialId, double> coefficient;        // ν or ε per region (not for the shell)
  std::optional<ShellRegion> shell;
  // Source s(x) per region (∫ s·∇v); empty = no volume source.
  std::function<Tensor<1, 2>(const Point<2> &, MaterialId)> vector_source;
  std::map<BoundaryId, std::function<double(const Point<2> &)>> dirichlet;
  std::vector<SurfaceCharge> surface_charges;
  std::vector<PeriodicPair> periodic;
  double solver_tolerance = 1e-12;                 // relative residual of CG
  unsigned int max_iterations = 5000;
  // CG + algebraic multigrid (scales to large and parallel problems), or a sparse direct
  // factorisation (MUMPS: robust against the μr contrast and the shell's anisotropy, and in
  // 2D faster than AMG up to a few 10^5 unknowns).
  enum class LinearSolver { cg_amg, direct } linear_solver = LinearSolver::cg_amg;
  // The backend the system is assembled and solved in: the configured one; only the test
  // that compares the backends asks for the other.
  LinearAlgebraBackend linear_algebra = LA;
  bool estimate_error = true; // run() ends with the Kelly indicator (estimate())
};

// What the solver did, for logs and for the error messages when it fails.
struct SolveReport
{
  LinearAlgebraBackend linear_algebra = LA;
  PotentialProblemDescription::LinearSolver linear_solver =
    PotentialProblemDescription::LinearSolver::cg_amg;
  dealii::types::global_dof_index n_dofs = 0;
  unsigned int n_cells = 0;
  unsigned int iterations = 0;
  double residual = 0.0;
  double setup_seconds = 0.0, assemble_seconds = 0.0, solve_seconds = 0.0;
  double estimated_error = 0.0; // Kelly indicator, summed over cells (l2)
};

class PotentialProblem
{
public:
  PotentialProblem(dealii::parallel::shared::Triangulation<2> &triangulation,
                   PotentialProblemDescription description);

  void run(); // setup_system → assemble_system → solve → estimate (if asked for)

  void setup_system();
  void assemble_system();
  void solve();
  void estimate();

  // Batch evaluation at arbitrary points (collective: every rank passes the same points and
  // receives all values). Throws if a point lies outside the mesh, unless `found` is given:
  // then it says which points were found (the others get 0).
  std::vector<double> values_at(const std::vector<Point<2>> &points,
                                std::vector<bool> *found = nullptr) const;
  std::vector<Tensor<1, 2>> gradients_at(const std::vector<Point<2>> &points) const;

  // ∫ K ∇u·∇u over the whole mesh (twice the field energy per unit length; the shell part is
  // the energy of the exterior it stands for).
  double energy_integral() const;

  // VTU (+ pvtu record) with u, the derived vector field and its magnitude, and region ids.
  // field_kind "magnetic": B = (∂A/∂y, −∂A/∂x); "electric": E = −∇Φ.
  void write_vtu(const std::string &directory, const std::string &basename,
                 const std::string &field_kind) const;

  const SolveReport &report() const { return solve_report; }
  const dealii::DoFHandler<2> &dof_handler() const { return dofs; }
  const dealii::Mapping<2> &mapping() const { return curved_mapping; }
  MPI_Comm communicator() const { return mpi_communicator; }

private:
  Tensor<2, 2> coefficient_at(const Point<2> &x, MaterialId material) const;
  void assemble_surface_charges(
    const dealii::DoFHandler<2>::active_cell_iterator &cell,
    dealii::Vector<double> &cell_rhs) const;

  MPI_Comm mpi_communicator;
  dealii::parallel::shared::Triangulation<2> &triangulation;
  PotentialProblemDescription description;

  dealii::FE_Q<2> fe;
  // MappingQ(p) through the manifolds, its support points computed once per cell (the
  // manifolds, the transfinite one above all, are expensive to query on every reinit).
  dealii::MappingQCache<2> curved_mapping;
  dealii::DoFHandler<2> dofs;

  dealii::IndexSet locally_owned_dofs;
  dealii::IndexSet locally_relevant_dofs;
  dealii::AffineConstraints<double> constraints;

  // Empty until setup_system makes the system of description.linear_algebra.
  std::variant<std::monostate, LinearSystem<LinearAlgebraBackend::petsc>,
               LinearSystem<LinearAlgebraBackend::trilinos>>
    linear_system;
  dealii::LinearAlgebra::distributed::Vector<double> ghosted_solution;
  dealii::Vector<float> error_indicator;

  SolveReport solve_report;
};

} // namespace magbrush::field
