// One more point of a finished study, run as that study's own point: `magbrush design gap|bias
// --refine` (the active study) uses it to spend DEM time where the answer is.
//
// A study folder (sweep_<NAME>/ of `magbrush sweep`) does not keep its command line, but it
// keeps what the command made: sweep_summary.csv lists the points in the sweep's order with the
// varied value as it was given, and every point's run folder has its variant.txt, the case
// file and every --set of that run. A point's --set, less its own (its varied value, its
// folder, its fields' folder, its seed), are the sweep's --set. The extended sweep is the
// same command with the new value appended to the --vary list, so that every earlier point
// keeps its index and its folder; it runs the new point alone (--point, once per repeat) and
// then rebuilds the study's tables and plots from all the folders (--merge).
//
// Not covered (refused, saying why): a study over several keys, a study forked from a
// spin-up, a study whose seeds were varied by hand rather than by --repeats.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace magbrush {

struct FinishedSweep
{
  std::filesystem::path dir;           // sweep_<NAME>/
  std::string name;                    // NAME
  std::string case_path;               // as the sweep was given it
  std::string key;                     // the varied key
  std::vector<std::string> values;     // as given, in the sweep's order, once each
  std::vector<std::string> overrides;  // the sweep's --set
  std::size_t repeats = 1;
};

FinishedSweep read_finished_sweep(const std::filesystem::path &dir, const std::string &key);

// The words after `magbrush` for the extended sweep: its --point runs (one per repeat) and
// its --merge. `stage_options` (e.g. --threads 1) go to every run.
std::vector<std::vector<std::string>> extended_sweep_commands(const FinishedSweep &sweep, const std::string &value,
                                                              const std::vector<std::string> &stage_options);

} // namespace magbrush
