// Reading a case file: YAML -> unit conversion -> overrides -> schema validation ->
// the resolved Case (case_model.h) -> geometric validation.
//
// Every error names the file, line and column, the key path, what was expected and what was
// found ("kawamoto_nip.yaml:14:8: drum.gap: expected a length (e.g. 25 mm), found '219 rpm'
// (that is an angular velocity)"), with a did-you-mean for unknown keys. As many errors as
// can be found are collected into one CaseError, one per line.
#pragma once

#include "case/case_model.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {

// The message is fully formatted (all errors, one per line after a summary line).
struct CaseError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

// Parses the file, converts units, applies overrides ("drum.gap=0.3mm",
// "roller.poles.N1.angle=95deg"; list elements are addressed by their name or [index]),
// validates (schema and geometry). Overrides go through the same validation as the file and
// errors in them name the override. Throws CaseError.
Case load_case(const std::string &path, const std::vector<std::string> &overrides = {});

// The same from text; `file_name_for_errors` is used in messages and as Case::source_file
// (its stem is the default case name).
Case parse_case_text(const std::string &yaml_text, const std::string &file_name_for_errors,
                     const std::vector<std::string> &overrides = {});

// Largest case file accepted (case files are small text files).
constexpr std::size_t max_case_file_bytes = 4u << 20;

} // namespace magbrush
