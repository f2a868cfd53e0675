// magbrush-field: the deal.II field stage of the pipeline (runs under mpirun).
//
//   magbrush-field CASE [--set key=value ...] [--only magnetic|electric] [--force] [--no-vtu]
//
// Reads the case, then for each field it needs: if the stored grid carries the case's hash the
// field is up to date and nothing is done; otherwise it is solved and stored (field_app.h).
#include "field_app.h"

#include "case_parser.h"

#include <deal.II/base/mpi.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace {

const char *usage =
  R"(Usage: magbrush-field CASE [--set key=value ...] [--only magnetic|electric] [--force] [--no-vtu]

Solves the fields of a case and stores them as grids in field.output_dir:
  magnetic  A_z of the magnet roller (shell-transformed open boundary), polar grid, sleeve
            and probe flux profiles (CSV), VTU for ParaView
  electric  the nip potential Φ on a window over the nip, VTU
A stored field whose case hash matches is reused ("up to date"); --force recomputes.
Run in parallel with: mpirun -np N magbrush-field CASE
)";

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;

  std::string case_path;
  std::vector<std::string> overrides;
  magbrush::field::FieldRunOptions options;
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    if (a == "--help" || a == "-h")
    {
      if (root)
        std::cout << usage;
      return 0;
    }
    else if (a == "--set" && i + 1 < args.size())
      overrides.push_back(args[++i]);
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (a == "--only" && i + 1 < args.size())
    {
      const std::string which = args[++i];
      if (which != "magnetic" && which != "electric")
      {
        if (root)
          std::cerr << "magbrush-field: --only expects 'magnetic' or 'electric', found '"
                    << which << "'\n";
        return 2;
      }
      options.magnetic = which == "magnetic";
      options.electric = which == "electric";
    }
    else if (a == "--force")
      options.force = true;
    else if (a == "--no-vtu")
      options.vtu = false;
    else if (!a.empty() && a[0] != '-' && case_path.empty())
      case_path = a;
    else
    {
      if (root)
        std::cerr << "magbrush-field: unknown argument '" << a << "'\n\n" << usage;
      return 2;
    }
  }
  if (case_path.empty())
  {
    if (root)
      std::cerr << usage;
    return 2;
  }

  try
  {
    const magbrush::Case c = magbrush::load_case(case_path, overrides);
    if (root)
      std::filesystem::create_directories(c.field.output_dir);
    MPI_Barrier(MPI_COMM_WORLD);
    if (options.magnetic)
      magbrush::field::compute_magnetic_field(c, options, MPI_COMM_WORLD);
    if (options.electric)
      magbrush::field::compute_electric_field(c, options, MPI_COMM_WORLD);
  }
  catch (const std::exception &e)
  {
    if (root)
      std::cerr << "magbrush-field: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
