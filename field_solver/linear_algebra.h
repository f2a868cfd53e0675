// The sparse linear algebra the field solver assembles and solves its systems in: PETSc or
// Trilinos, both through deal.II's wrappers, one chosen when the build is configured
//
//     cmake -DMAGBRUSH_LINEAR_ALGEBRA=PETSc|Trilinos      (default PETSc)
//
// as deal.II's step-40 chooses its LA namespace. Every field solve uses the configured one
// (`LA` below). The assembly and the solve are written once, over the backend
// (potential_problem.cpp, linear_system.h); the other backend is compiled in as well (deal.II
// has both), so that a test can solve the same problem in both and compare them.
//
// PETSc is the default: the design names it, it runs both of the field solver's solves natively
// (MUMPS, which Trilinos reaches through Amesos, and hypre's BoomerAMG, with which CG needs 4–8×
// fewer iterations than with ML on the default cases), and there it costs the same time and
// memory as Trilinos (docs/pipeline_cost.md).
//
// Free of deal.II: the driver names the backend in `magbrush field --help` without linking it.
#pragma once

namespace magbrush::field {

enum class LinearAlgebraBackend { petsc, trilinos };

// CMake defines exactly one of these on every target that reads this header
// (the magbrush_linear_algebra interface library, field_solver/CMakeLists.txt).
#if defined(MAGBRUSH_LINEAR_ALGEBRA_PETSC)
inline constexpr LinearAlgebraBackend LA = LinearAlgebraBackend::petsc;
#elif defined(MAGBRUSH_LINEAR_ALGEBRA_TRILINOS)
inline constexpr LinearAlgebraBackend LA = LinearAlgebraBackend::trilinos;
#else
#error "no linear-algebra backend configured: link magbrush_linear_algebra (field_solver/CMakeLists.txt)"
#endif

// What the logs and the help call a backend and its two solvers.
struct LinearAlgebraNames
{
  const char *backend;
  const char *direct_solver;    // the sparse factorisation
  const char *iterative_solver; // CG with algebraic multigrid
};

constexpr LinearAlgebraNames names_of(LinearAlgebraBackend backend)
{
  return backend == LinearAlgebraBackend::petsc
           ? LinearAlgebraNames{"PETSc", "MUMPS", "CG + BoomerAMG (hypre)"}
           : LinearAlgebraNames{"Trilinos", "MUMPS through Amesos", "CG + ML AMG"};
}

} // namespace magbrush::field
