// How much each requirement moves when each pole moves: the table a designer reads to set
// tolerances ("S2 made 10 kA/m weaker lowers the release arc's |B| by …"). Central
// differences on the exact ring at the designed layout, for every pole (fixed ones too: a
// fixed pole still has a manufacturing tolerance), per 1° of angle and per 10 kA/m of |M|.
#pragma once

#include "design/design_requirements.h"
#include "design/ring_profile.h"

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace magbrush {

struct SensitivityTable
{
  std::vector<std::string> requirements; // "S1 peak |Bn| [mT]"
  std::vector<std::string> parameters;   // "S1 angle", "S1 |M|"
  std::vector<bool> per_degree;          // true: per 1°, false: per 10 kA/m
  Eigen::MatrixXd d;                     // d(requirement value) per unit change of the parameter
};

SensitivityTable sensitivities(const RequirementSet &requirements, const RingProfile &ring,
                               const std::vector<Pole> &poles);

// The table as aligned text, and as CSV (requirement, unit, then one column per parameter).
std::string format_sensitivities(const SensitivityTable &t);
std::string sensitivities_csv(const SensitivityTable &t);

} // namespace magbrush
