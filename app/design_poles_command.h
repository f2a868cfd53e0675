// `magbrush design poles CASE --target FILE ...` (app/cmd_design.cpp declares the options).
#pragma once

#include "common/command_line.h"

namespace magbrush {
int run_design_poles(const cli::ParsedArguments &args);
}
