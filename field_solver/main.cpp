// magbrush-field: the deal.II field stage of the pipeline (runs under mpirun).
//
//   magbrush-field CASE [--set key=value ...] [--only magnetic|electric] [--force] [--no-vtu]
//
// Reads the case, then for each field it needs: if the stored grid carries the case's hash the
// field is up to date and nothing is done; otherwise it is solved and stored (field_app.h).
#include "field_solver/field_app.h"
#include "field_solver/field_command_line.h"

#include "case/case_parser.h"

#include <deal.II/base/mpi.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace {

// The solver's options, declared once for it and for `magbrush field` (field_command_line.h).
const magbrush::cli::CommandSpec &command_line()
{
  static const magbrush::cli::CommandSpec spec = [] {
    magbrush::cli::CommandSpec s = magbrush::field::solver_command_line("magbrush-field");
    s.epilog = "Run in parallel with: mpirun -np N magbrush-field CASE (or magbrush field CASE -np N)\n";
    return s;
  }();
  return spec;
}

// What the command line asks for; only the first process prints help and mistakes.
std::optional<magbrush::cli::ParsedArguments> parse_command_line(int argc, char **argv, bool root, int &exit_code)
{
  try
  {
    auto arguments = magbrush::cli::parse(command_line(), {argv + 1, argv + argc});
    if (!arguments.help_requested())
      return arguments;
    if (root)
      std::cout << magbrush::cli::help_text(command_line());
    exit_code = 0;
  }
  catch (const magbrush::cli::UsageError &e)
  {
    if (root)
      std::cerr << magbrush::cli::usage_error_text(command_line(), e.what());
    exit_code = 2;
  }
  return std::nullopt;
}

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;

  int exit_code = 0;
  const auto arguments = parse_command_line(argc, argv, root, exit_code);
  if (!arguments)
    return exit_code;
  const std::string case_path = arguments->positional(0);
  const std::vector<std::string> overrides = arguments->values("--set");
  magbrush::field::FieldRunOptions options;
  if (arguments->has("--only"))
  {
    options.magnetic = arguments->value("--only") == "magnetic";
    options.electric = arguments->value("--only") == "electric";
  }
  options.force = arguments->has("--force");
  options.vtu = !arguments->has("--no-vtu");

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
