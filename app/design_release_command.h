// `magbrush design release CASE [--vary key=v1,v2,...] [--window FROM,TO]` (app/cmd_design.cpp
// declares the options).
#pragma once

#include "common/command_line.h"

namespace magbrush {
int run_design_release(const cli::ParsedArguments &args);
}
