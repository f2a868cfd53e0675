// The command line of the DEM engine, declared once for the two programs that take it: the
// engine itself (magbrush-dem) and the driver's `magbrush dem`, which checks the arguments
// and hands them on. Header-only, so that the driver reads it without linking the engine.
#pragma once

#include "common/command_line.h"

#include <string>

namespace magbrush::dem {

// `program` starts the usage and every message: "magbrush-dem" or "magbrush dem".
inline cli::CommandSpec engine_command_line(const std::string &program)
{
  cli::CommandSpec spec;
  spec.program = program;
  spec.usage = program + " CASE [--set key=value ...] [--restart FILE [--restart-anyway] | --resume] [--threads N] [--output DIR]";
  spec.description =
      "Runs the particles of a case with the discrete-element engine (bin/magbrush-dem): inserts\n"
      "the populations, lets them settle (dem.settle_time), then runs to dem.duration. Outputs in\n"
      "<output.directory>/dem/: particles.xdmf (open in ParaView), snapshots/*.h5, time_series.csv\n"
      "(energies, contacts, wall forces and torques), checkpoint.bin.\n";
  spec.positionals = {{"CASE", "the case file"}};
  spec.options = {
      cli::set_option(),
      {"--restart", {}, "FILE", "continue from a checkpoint, bit-identically to an uninterrupted run"},
      {"--restart-anyway", {}, {},
       "restart even when the checkpoint's case differs from this one beyond run control\n(particle counts, materials, walls, settings: refused otherwise, with the keys)"},
      {"--resume", {}, {},
       "continue from the output folder's own checkpoint.bin when there is one (a run stopped by a\n"
       "time limit, by hand or by a crash: the files then cover the whole run), else start afresh"},
      {"--threads", {}, "N", "OpenMP threads (default: dem.threads, then all cores); results do not\ndepend on it"},
      {"--output", {}, "DIR", "write the outputs here instead of <output.directory>/dem",
       /*repeatable=*/false, /*choices=*/{}, /*for_pipeline=*/false}};
  spec.epilog =
      "A run that becomes unstable (NaN, overlap beyond dem.max_overlap_fraction, kinetic-energy\n"
      "runaway) stops with exit code 3 and a message naming the step, the particle, the cause and\n"
      "the likely fix; the last good checkpoint is kept.\n"
      "\n"
      "Checkpoints: every dem.checkpoint_interval of simulated time, every\n"
      "dem.checkpoint_wall_interval of wall time and at the end, each with a checksum and the\n"
      "case's inputs; the one before is kept as checkpoint.previous.bin. A damaged checkpoint is\n"
      "refused before anything is read; a restart under a case that differs beyond run control\n"
      "(duration, intervals, threads, output, what is measured and over which window) is refused\n"
      "with the keys that differ.\n";
  return spec;
}

} // namespace magbrush::dem
