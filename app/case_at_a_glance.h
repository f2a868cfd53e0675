// What `magbrush run` prints about the case before it runs: ten lines a designer reads at a
// glance (which case, which variant and folder, the roller, the drum and gap, the electric
// field, the particles, the run's length and its averaging windows), instead of the ~230
// lines of the resolved case, which go to <run folder>/case_resolved.txt.
#pragma once

#include "case/case_model.h"

#include <string>

namespace magbrush {

// `resolved_file`: where the whole resolved case was written (named on the last line).
std::string case_at_a_glance(const Case &c, const std::string &resolved_file);

} // namespace magbrush
