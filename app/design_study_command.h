// `magbrush design gap|bias --target VALUE STUDY_DIR ...` (app/cmd_design.cpp declares the options).
#pragma once

#include "common/command_line.h"

#include <string>

namespace magbrush {
int run_design_study(const cli::ParsedArguments &args, const std::string &mode);
}
