// Printing: the resolved case with units (what `magbrush check` shows), the numbers a
// designer derives from it, and the schema reference (`magbrush check --explain`).
#pragma once

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush {

// One resolved leaf of a case: its key path (list elements by name: "roller.poles.N1.angle"),
// its schema pattern ("roller.poles[].angle"), the value at full precision in SI ("exact",
// used for hashing) and as a user would write it ("pretty", e.g. "25 mm").
struct ResolvedEntry
{
  std::string path;
  std::string pattern;
  std::string exact;
  std::string pretty;
};

// Every input of the case, after defaults, in schema order. Generated blades appear as their
// profile polygon; the sleeve and drum sizes as radii.
std::vector<ResolvedEntry> resolved_entries(const Case &c);

// The resolved case as indented "key: value" lines with units (valid case-file syntax).
std::string format_case(const Case &c);

// Derived numbers: surface speeds, relative speed at the nip, particle counts and masses, the
// magnetic pressure of a uniform applied field. (The pole model's sleeve-surface field needs
// the exact ring: fields/pole_field_summary.h.)
std::string format_derived(const Case &c);

// The schema as a table: plain text, or Markdown for docs/case_reference.md.
std::string format_schema(bool markdown);

} // namespace magbrush
