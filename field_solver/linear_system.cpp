#include "field_solver/linear_system.h"

#include <deal.II/lac/petsc_precondition.h>
#include <deal.II/lac/petsc_solver.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>

namespace magbrush::field {

using namespace dealii;

namespace {

// deal.II's CG for both backends: one convergence test (SolverControl on the unpreconditioned
// residual), so a tolerance and an iteration count compare across backends.
template <class SparseMatrix, class Vector, class Preconditioner>
void conjugate_gradients(const SparseMatrix &matrix, Vector &x, const Vector &rhs,
                         const Preconditioner &preconditioner, SolverControl &control)
{
  SolverCG<Vector> cg(control);
  cg.solve(matrix, x, rhs, preconditioner);
}

} // namespace

// PETSc's own interface to MUMPS. LU rather than its symmetric LDLᵀ mode: the same
// factorisation as the Trilinos path, so that the two backends solve alike.
void LinearSystem<LinearAlgebraBackend::petsc>::solve_direct(Vector &x) const
{
  SolverControl control(1, 0.0, false, false);
  PETScWrappers::SparseDirectMUMPS mumps(control, matrix.get_mpi_communicator());
  mumps.solve(matrix, x, rhs);
}

// hypre's BoomerAMG told that the operator is symmetric (symmetric relaxation, which CG needs);
// its default strong threshold 0.25 is hypre's recommendation in 2D.
void LinearSystem<LinearAlgebraBackend::petsc>::solve_cg_amg(Vector &x, SolverControl &control,
                                                      unsigned int /*degree*/) const
{
  PETScWrappers::PreconditionBoomerAMG::AdditionalData data;
  data.symmetric_operator = true;
  const PETScWrappers::PreconditionBoomerAMG amg(matrix, data);
  conjugate_gradients(matrix, x, rhs, amg, control);
}

// MUMPS (nested-dissection ordering, BLAS kernels) through Amesos: several times faster than
// Amesos' default KLU on finite-element matrices.
void LinearSystem<LinearAlgebraBackend::trilinos>::solve_direct(Vector &x) const
{
  SolverControl control(1, 0.0, false, false);
  TrilinosWrappers::SolverDirect direct(
    control, TrilinosWrappers::SolverDirect::AdditionalData(false, "Amesos_Mumps"));
  direct.solve(matrix, x, rhs);
}

// ML for an elliptic operator, told when the elements are of higher order; two smoother
// sweeps and an aggregation threshold of 0.02 against the μr contrast.
void LinearSystem<LinearAlgebraBackend::trilinos>::solve_cg_amg(Vector &x, SolverControl &control,
                                                         unsigned int degree) const
{
  TrilinosWrappers::PreconditionAMG amg;
  TrilinosWrappers::PreconditionAMG::AdditionalData data;
  data.elliptic = true;
  data.higher_order_elements = degree > 1;
  data.smoother_sweeps = 2;
  data.aggregation_threshold = 0.02;
  amg.initialize(matrix, data);
  conjugate_gradients(matrix, x, rhs, amg, control);
}

} // namespace magbrush::field
