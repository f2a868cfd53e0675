// The assembled system K u = f of a potential problem in one linear-algebra backend
// (linear_algebra.h): its distributed sparse matrix and right-hand side, and the two ways the
// field solver solves it. Only these differ between PETSc and Trilinos; PotentialProblem
// assembles into either through the same code (the wrappers share reinit, compress and
// AffineConstraints::distribute_local_to_global), and the Krylov method is deal.II's own
// SolverCG for both, so that the convergence test, the tolerance and the iteration count mean
// the same whichever backend solved.
//
//   direct   MUMPS, LU (PETSc natively; Trilinos through Amesos_Mumps)
//   cg_amg   CG preconditioned by one V-cycle of algebraic multigrid for a symmetric
//            positive-definite operator: hypre's BoomerAMG (PETSc) or ML (Trilinos)
#pragma once

#include "field_solver/linear_algebra.h"

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

namespace magbrush::field {

// One full specialisation per backend: the same members, each backend's types; the two
// solves are defined in linear_system.cpp, the only file that needs the solvers' headers.
template <LinearAlgebraBackend backend>
struct LinearSystem;

template <>
struct LinearSystem<LinearAlgebraBackend::petsc>
{
  using Vector = dealii::PETScWrappers::MPI::Vector;
  using SparseMatrix = dealii::PETScWrappers::MPI::SparseMatrix;

  SparseMatrix matrix;
  Vector rhs;

  // x = K⁻¹ f by a sparse LU factorisation (x: the locally owned entries).
  void solve_direct(Vector &x) const;
  // x by CG + AMG until `control` is satisfied (throws SolverControl::NoConvergence if it is
  // not); `degree` of the FE_Q elements.
  void solve_cg_amg(Vector &x, dealii::SolverControl &control, unsigned int degree) const;
};

template <>
struct LinearSystem<LinearAlgebraBackend::trilinos>
{
  using Vector = dealii::TrilinosWrappers::MPI::Vector;
  using SparseMatrix = dealii::TrilinosWrappers::SparseMatrix;

  SparseMatrix matrix;
  Vector rhs;

  void solve_direct(Vector &x) const;
  void solve_cg_amg(Vector &x, dealii::SolverControl &control, unsigned int degree) const;
};

} // namespace magbrush::field
