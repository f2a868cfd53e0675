// The folder a run writes into when the case does not name one (output.directory empty):
//   results/<case name>/                    the case as its file gives it
//   results/<case name>-<6 hex digits>/     a variant: the digest of its sorted --set overrides
// so that a variant never overwrites its baseline or another variant, and the same overrides
// (in any order) always find the same folder again: stage reuse by input hash keeps working.
// The stored fields follow the same rule with only the overrides that change a field
// (results/<case name>[-<digest of those>]/fields): a variant that changes DEM keys only reads
// its baseline's fields instead of solving them again.
#pragma once

#include <string>
#include <vector>

namespace magbrush {

// Where automatic run folders go, and a sweep's folder (sweep_<NAME>/) when the case names none.
inline const char *const results_root_directory = "results";

// The overrides as a variant's identity: "key=value" with the spaces around both trimmed,
// sorted, each key once (the last one given wins, as in the case).
std::vector<std::string> normalised_overrides(const std::vector<std::string> &overrides);

// Six hex digits of the FNV-1a digest of the normalised overrides, one per line.
std::string overrides_digest(const std::vector<std::string> &normalised);

// results/<name> or results/<name>-<digest> (no overrides: no digest).
std::string automatic_run_folder(const std::string &case_name, const std::vector<std::string> &normalised);

// variant.txt: the case file and the overrides that made this folder, one per line, so that
// a folder named by a digest says what it holds (and `magbrush compare` can list them).
std::string variant_text(const std::string &case_file, const std::vector<std::string> &normalised);

} // namespace magbrush
