// The design's page: index.md and index.html in the folder of `magbrush design poles`, the
// page a designer decides from — the verdict, the profile against the target band (the PNG),
// every requirement met or missed on the exact ring and on the FEM, the layout against the
// case's, the constraints that bind, and the sensitivity table. The run report of the case
// (tools/report.py) links it and shows its profile and requirements when the run folder has a
// design/ folder.
#pragma once

#include "design/design_requirements.h"
#include "design/design_sensitivity.h"

#include <string>
#include <vector>

namespace magbrush {

struct DesignPage
{
  std::string case_name, target, verdict, method, time;
  std::string image;                                // design_profile.png, or empty when not drawn
  std::vector<std::vector<std::string>> layout;     // pole, angle case, designed, |M| case, designed, free/fixed
  std::vector<RequirementResult> ring, fem;         // fem empty: no FEM check
  std::string fem_note;                             // the FEM against the exact ring, or why not checked
  std::vector<std::string> binding;
  SensitivityTable sensitivity;
  std::vector<std::string> files;                   // the folder's other outputs, by name
};

void write_design_page(const std::string &dir, const DesignPage &page);

} // namespace magbrush
