// The case-file schema: the single place where every key's type, dimension, default, range,
// documentation and field dependency live. Each module declares its own keys in
// case/case_keys_<module>.cpp; the schema is their union (case_keys.h lists the modules).
// The parser validates against it, `magbrush check --explain` prints it,
// docs/case_reference.md is generated from it, and the field hashes (case_hash.h) select their
// inputs by its `affects` marks.
//
// Keys are written as patterns: "roller.poles[].angle" (an element of a list),
// "materials.*.density" (an entry of a map keyed by a user-chosen name).
#pragma once

#include "case/units.h"

#include <optional>
#include <string>
#include <vector>

namespace magbrush {

enum class KeyType
{
  section,     // a mapping with the fixed keys listed under it
  list,        // a sequence of sections (pattern + "[]")
  map,         // a mapping name -> section (pattern + ".*")
  quantity,    // number with unit of `dimension`
  integer,
  boolean,
  string,
  choice,      // one of `choices`
  vector3,     // [x, y, z], each a quantity of `dimension`
  polygon,     // [[x, y], ...] lengths, at least 3 points
  box,         // [[x, y, z], [x, y, z]] lengths: min and max corners
};

// Which stored field a key changes (a field file is regenerated when its inputs change).
enum class Affects
{
  none,
  magnetic,
  electric,
  both,
};

struct KeySpec
{
  std::string path;          // pattern, e.g. "roller.poles[].angle"
  KeyType type = KeyType::section;
  Dimension dimension = Dimension::dimensionless;
  std::string default_text;  // as written in a case file; "" = no default
  bool required = false;
  std::optional<double> min; // SI
  std::optional<double> max; // SI
  bool min_inclusive = true;
  bool max_inclusive = true;
  std::vector<std::string> choices;
  std::string doc;
  Affects affects = Affects::none;

  bool is_container() const
  {
    return type == KeyType::section || type == KeyType::list || type == KeyType::map;
  }
  std::string type_description() const; // "length", "integer", "one of: carrier, toner", ...
  std::string range_description() const; // "> 0", "in [0 deg, 360 deg)", "" if none
};

// All keys, parents before children, in the order of the reference documentation: the
// modules' declarations in the order of key_declarations() (case_keys.h).
const std::vector<KeySpec> &case_schema();

// The spec of a pattern, or nullptr.
const KeySpec *find_key_spec(const std::string &pattern);

// The keys directly under a section pattern ("" = top level).
std::vector<const KeySpec *> child_key_specs(const std::string &section_pattern);

// The closest of `candidates` to `word` (Damerau–Levenshtein, case-insensitive), if close
// enough to be a plausible typo; "" otherwise.
std::string did_you_mean(const std::string &word, const std::vector<std::string> &candidates);

// "a.b[].c" -> "a.b[]", "" for top-level keys; and the last component ("c").
std::string parent_pattern(const std::string &pattern);
std::string last_component(const std::string &pattern);

} // namespace magbrush
