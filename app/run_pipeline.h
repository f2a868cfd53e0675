// The pipeline of `magbrush run` as a function, so that `magbrush sweep` runs it once per
// point of a parameter sweep. `args` as a subcommand receives them: {"run", CASE, options...}.
//
// Both commands accept, besides their own options, every option a stage of the pipeline
// declares for it (-np and --force of the field, --threads of the DEM, ...), and each stage
// receives only the options it declares itself: the list is read from the stages'
// declarations (Subcommand::command_line), never written by hand.
#pragma once

#include "common/command_line.h"

#include <string>
#include <vector>

namespace magbrush {

int run_pipeline(const std::vector<std::string> &args);

// The stages, in the order they run.
const std::vector<std::string> &pipeline_stages();

// The options the stages declare for the pipeline (all but --set, which `run` and `sweep`
// declare themselves), each once, its help ending with the stages it goes to: "[field]".
std::vector<cli::Option> stage_options();

} // namespace magbrush
