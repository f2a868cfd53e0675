// Small, coarse cases built in code for the geometry tests (no case file needed): a 5-pole
// roller with a soft-magnetic doctor blade and a non-magnetic guide, and the nip with and
// without a photoconductor layer.
#pragma once

#include "case/case_model.h"

#include <string>

namespace magbrush::testing {

Case coarse_roller_case();                    // sleeve 10 mm, magnetic blade + plain guide
Case coarse_nip_case(double pc_thickness);    // sleeve 10 mm, drum 15 mm, gap 0.35 mm
std::string scratch_dir(const std::string &name); // an empty directory under the build tree (per process)

} // namespace magbrush::testing
