// `magbrush flux CASE --compare OTHER`: the sleeve-flux profiles of two cases (or of a case and
// a variant of it) overlaid, with how far each pole's peak moved between them.
//
// A designer who moves a pole, changes its strength or its shape wants the before and after
// of the field on the sleeve before spending a DEM run on the change. Both profiles come from
// the same source — the finite-element profile when `magbrush field` has stored one for each
// case as it is now, else the exact multipole ring for both — so the difference is the
// layouts', not the solvers'.
#pragma once

#include <string>
#include <vector>

namespace magbrush {

struct FluxCaseComparisonOptions
{
  std::string case_path, other_path;
  std::vector<std::string> overrides;       // --set: both cases
  std::vector<std::string> other_overrides; // --compare-set: the other case only, after --set
  std::string output_dir;                   // "" = <CASE's run folder>/flux/compare_<OTHER's folder>
  std::string source = "auto";              // auto | ring | fem
  int harmonics = 0;                        // 0 = chosen from the series' decay
  bool no_plot = false;
};

// Prints the per-pole table, writes flux_compare.csv (both profiles, 0.25° steps),
// flux_compare_peaks.csv (each pole: angle and Bn in each case, the shift, the change) and
// flux_compare.png; returns the exit status (0). Throws std::invalid_argument on bad input.
int compare_case_fluxes(const FluxCaseComparisonOptions &options);

} // namespace magbrush
