// The command line of the field solver, declared once for the two programs that take it: the
// solver itself (magbrush-field) and the driver's `magbrush field`, which adds -np and starts
// the solver (under mpirun for more than one process). Header-only, so that the driver reads
// it without linking deal.II.
#pragma once

#include "common/command_line.h"
#include "field_solver/linear_algebra.h"

#include <string>

namespace magbrush::field {

// `program` starts the usage and every message: "magbrush-field" or "magbrush field".
inline cli::CommandSpec solver_command_line(const std::string &program)
{
  cli::CommandSpec spec;
  spec.program = program;
  spec.usage = program + " CASE [--set key=value ...] [--only magnetic|electric] [--force] [--no-vtu]";
  spec.description =
      "Solves the magnetic field of the roller (and the nip's electric field) of a case with the\n"
      "finite-element solver and stores them as grids in field.output_dir:\n"
      "  magnetic  A_z of the magnet roller (shell-transformed open boundary), polar grid, sleeve\n"
      "            and probe flux profiles (CSV), VTU for ParaView\n"
      "  electric  the nip potential on a window over the nip, VTU\n"
      "A stored field whose case hash still matches is reused (\"up to date\"); only the field whose\n"
      "inputs changed is recomputed.\n"
      "Linear algebra: " + std::string(names_of(LA).backend) +
      ", chosen when building (cmake -DMAGBRUSH_LINEAR_ALGEBRA=PETSc|Trilinos):\n"
      "  on one process the sparse direct solver " + names_of(LA).direct_solver +
      ", in parallel " + names_of(LA).iterative_solver + ".\n";
  spec.positionals = {{"CASE", "the case file"}};
  spec.options = {
      cli::set_option(),
      {"--only", {}, "magnetic|electric", "solve only the magnetic or only the electric field",
       /*repeatable=*/false, /*choices=*/{"magnetic", "electric"}, /*for_pipeline=*/false},
      {"--force", {}, "", "recompute even when the stored field is up to date"},
      {"--no-vtu", {}, "", "write no ParaView (VTU) files"}};
  return spec;
}

} // namespace magbrush::field
