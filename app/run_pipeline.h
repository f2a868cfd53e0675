// The pipeline of `magbrush run` as a function, so that `magbrush sweep` runs it once per
// point of a parameter sweep. `args` as a subcommand receives them: {"run", CASE, options...}.
#pragma once

#include <string>
#include <vector>

namespace magbrush {

int run_pipeline(const std::vector<std::string> &args);

} // namespace magbrush
