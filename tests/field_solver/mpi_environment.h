// deal.II's parallel triangulation and the PETSc and Trilinos solvers need MPI; GoogleTest's
// main does not start it. This global environment does (once per test program, single rank).
#pragma once

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <memory>

namespace magbrush::field::testing {

class MpiEnvironment : public ::testing::Environment
{
public:
  void SetUp() override
  {
    static int argc = 1;
    static char name[] = "field_test";
    static char *argv_storage[] = {name, nullptr};
    static char **argv = argv_storage;
    mpi = std::make_unique<dealii::Utilities::MPI::MPI_InitFinalize>(argc, argv, 1);
  }
  void TearDown() override { mpi.reset(); }

private:
  std::unique_ptr<dealii::Utilities::MPI::MPI_InitFinalize> mpi;
};

inline ::testing::Environment *const mpi_environment =
  ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

} // namespace magbrush::field::testing
