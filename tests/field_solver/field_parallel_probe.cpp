// Solves the five-pole roller and writes B on the sleeve circle to a file (rank 0), so that
// test_parallel can compare a serial run with an `mpirun -np 2` run of the same problem.
//   field_parallel_probe OUTPUT_FILE
#include "field_solver/roller_magnetostatics.h"

#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdio>
#include <iostream>

using namespace magbrush;
using namespace magbrush::field;

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc != 2)
  {
    std::cerr << "usage: field_parallel_probe OUTPUT_FILE\n";
    return 2;
  }
  try
  {
    const double deg = 3.14159265358979323846 / 180.0;
    RollerGeometry g;
    g.shaft_radius = 3e-3;
    g.shaft_mu_r = 1000.0;
    g.magnet_radius = 9.3e-3;
    g.sleeve_radius = 10e-3;
    const std::vector<Pole> poles = {{"S1", 0 * deg, -330e3, 10.0},
                                     {"N1", 72 * deg, 172e3, 10.0},
                                     {"S2", 144 * deg, -200e3, 10.0},
                                     {"S3", 216 * deg, -170e3, 10.0},
                                     {"N2", 288 * deg, 142e3, 10.0}};
    RollerDiscretisation disc;
    disc.n_angular = 48;
    disc.refinements = 1;
    disc.solver_tolerance = 1e-13;
    RollerMagnetostatics solver(MPI_COMM_WORLD, g, gaussian_pole_magnetisation(poles), disc);
    solver.run();
    const auto profile = solver.profile(10.5e-3, 90);
    if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    {
      FILE *out = std::fopen(argv[1], "w");
      if (!out)
      {
        std::cerr << "field_parallel_probe: cannot write " << argv[1] << "\n";
        return 1;
      }
      std::fprintf(out, "%u %u\n", dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD),
                   solver.problem().report().iterations);
      for (std::size_t k = 0; k < profile.angle.size(); ++k)
        std::fprintf(out, "%.17g %.17g %.17g\n", profile.angle[k], profile.Bn[k],
                     profile.Bt[k]);
      std::fclose(out);
    }
  }
  catch (const std::exception &e)
  {
    std::cerr << "field_parallel_probe: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
