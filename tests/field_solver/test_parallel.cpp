// Serial and `mpirun -np 2` solves of the same roller problem must agree to the solver
// tolerance (METIS partitioning, CG + AMG of the configured linear-algebra backend). Runs the
// probe program under mpirun.
#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace {

struct Probe
{
  unsigned int ranks = 0, iterations = 0;
  std::vector<double> Bn, Bt;
};

Probe run_probe(int ranks)
{
  // OpenMPI refuses to run as root (containers, CI) unless told that this is intended.
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const std::string out = (magbrush::testing::test_temp_dir("field_parallel") /
                           ("probe_np" + std::to_string(ranks) + ".txt")).string();
  std::remove(out.c_str());
  const std::string command = "mpirun --oversubscribe -np " + std::to_string(ranks) + " " +
                              MAGBRUSH_BINARY_DIR + "/tests/field_parallel_probe " + out +
                              " > " + out + ".log 2>&1";
  const int rc = std::system(command.c_str());
  Probe p;
  EXPECT_EQ(rc, 0) << command << " failed; see " << out << ".log";
  std::ifstream in(out);
  in >> p.ranks >> p.iterations;
  double angle, bn, bt;
  while (in >> angle >> bn >> bt)
  {
    p.Bn.push_back(bn);
    p.Bt.push_back(bt);
  }
  return p;
}

} // namespace

TEST(FieldParallel, SerialAndTwoRanksAgree)
{
  // Without an MPI launcher there is nothing to compare: say so instead of passing.
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "mpirun not found: the serial/parallel comparison is not run";
  const Probe serial = run_probe(1);
  const Probe parallel = run_probe(2);
  ASSERT_EQ(serial.ranks, 1u);
  ASSERT_EQ(parallel.ranks, 2u);
  ASSERT_EQ(serial.Bn.size(), 90u);
  ASSERT_EQ(parallel.Bn.size(), serial.Bn.size());
  double peak = 0.0, diff = 0.0;
  for (std::size_t k = 0; k < serial.Bn.size(); ++k)
  {
    peak = std::max(peak, std::hypot(serial.Bn[k], serial.Bt[k]));
    diff = std::max(diff, std::hypot(serial.Bn[k] - parallel.Bn[k],
                                     serial.Bt[k] - parallel.Bt[k]));
  }
  std::printf("serial vs 2 ranks: max |ΔB| / peak = %.3e (CG iterations %u vs %u)\n",
              diff / peak, serial.iterations, parallel.iterations);
  EXPECT_GT(peak, 0.01); // a real field, not two zeros
  EXPECT_LT(diff / peak, 1e-9);
}
