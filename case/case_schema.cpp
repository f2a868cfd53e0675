// The case-file schema: the union of the keys each module declares in its own
// case/case_keys_<module>.cpp (the list, its order and why it is explicit: case_keys.h),
// and the look-ups the parser, the printer and the docs use on it.
#include "case/case_schema.h"

#include "case/case_keys.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>

namespace magbrush {

// The order of the reference documentation: parents before children, a module that adds keys
// to another's section after that module.
const std::vector<KeyDeclaration> &key_declarations()
{
  static const std::vector<KeyDeclaration> modules{
      {"scene", "case/case_keys_scene.cpp", &case_keys::scene_keys},
      {"geometry", "case/case_keys_geometry.cpp", &case_keys::geometry_keys},
      {"particles", "case/case_keys_particles.cpp", &case_keys::particle_keys},
      {"electric", "case/case_keys_electric.cpp", &case_keys::electric_keys},
      {"applied_field", "case/case_keys_applied_field.cpp", &case_keys::applied_field_keys},
      {"field_solver", "case/case_keys_field_solver.cpp", &case_keys::field_solver_keys},
      {"dem", "case/case_keys_dem.cpp", &case_keys::dem_keys},
      {"magnetics", "case/case_keys_magnetics.cpp", &case_keys::magnetic_keys},
      {"flow", "case/case_keys_flow.cpp", &case_keys::flow_keys},
      {"measurements", "case/case_keys_measurements.cpp", &case_keys::measurement_keys},
      {"output", "case/case_keys_output.cpp", &case_keys::output_keys},
  };
  return modules;
}

namespace {

// Assembles the union of the module declarations and checks what a reader of the schema relies
// on: no key is declared twice, and every key's section is declared before it (the parser,
// `--explain` and the generated reference walk the schema top down). A broken declaration
// stops every program at its first look at the schema, not just the one that reads the key.
std::vector<KeySpec> build_schema()
{
  std::vector<KeySpec> schema;
  std::set<std::string> declared;
  for (const auto &module : key_declarations())
    for (auto &key : module.declare())
    {
      const std::string where = std::string(" (") + module.file + ")";
      if (declared.count(key.path))
        throw std::logic_error("case schema: key " + key.path + " declared twice" + where);
      std::string parent = parent_pattern(key.path);
      for (const char *element : {"[]", ".*"})
        if (parent.size() > 2 && parent.compare(parent.size() - 2, 2, element) == 0)
          parent.resize(parent.size() - 2);
      if (!parent.empty() && !declared.count(parent))
        throw std::logic_error("case schema: key " + key.path + " comes before its section " + parent + where);
      declared.insert(key.path);
      schema.push_back(std::move(key));
    }
  return schema;
}

std::string lower(std::string s)
{
  for (auto &c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Optimal string alignment distance (Damerau–Levenshtein with adjacent transpositions).
size_t edit_distance(const std::string &a, const std::string &b)
{
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<size_t>> d(n + 1, std::vector<size_t>(m + 1));
  for (size_t i = 0; i <= n; ++i)
    d[i][0] = i;
  for (size_t j = 0; j <= m; ++j)
    d[0][j] = j;
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j)
    {
      const size_t cost = (a[i - 1] == b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

std::string format_bound(double v, Dimension d) { return format_quantity(v, d); }

// "a length" -> "length"
std::string without_article(const std::string &s)
{
  if (s.rfind("a ", 0) == 0)
    return s.substr(2);
  if (s.rfind("an ", 0) == 0)
    return s.substr(3);
  return s;
}

} // namespace

const std::vector<KeySpec> &case_schema()
{
  static const std::vector<KeySpec> schema = build_schema();
  return schema;
}

const KeySpec *find_key_spec(const std::string &pattern)
{
  for (const auto &k : case_schema())
    if (k.path == pattern)
      return &k;
  return nullptr;
}

std::string parent_pattern(const std::string &pattern)
{
  const auto dot = pattern.find_last_of('.');
  if (dot == std::string::npos)
    return "";
  std::string parent = pattern.substr(0, dot);
  // "a.b[]" is the element of list "a.b"; "materials.*" is the entry of map "materials":
  // both are the section whose keys we list.
  return parent;
}

std::string last_component(const std::string &pattern)
{
  const auto dot = pattern.find_last_of('.');
  return dot == std::string::npos ? pattern : pattern.substr(dot + 1);
}

std::vector<const KeySpec *> child_key_specs(const std::string &section_pattern)
{
  std::vector<const KeySpec *> children;
  for (const auto &k : case_schema())
    if (parent_pattern(k.path) == section_pattern)
      children.push_back(&k);
  return children;
}

std::string did_you_mean(const std::string &word, const std::vector<std::string> &candidates)
{
  std::string best;
  size_t best_distance = std::string::npos;
  for (const auto &c : candidates)
  {
    const size_t d = edit_distance(lower(word), lower(c));
    if (d < best_distance)
    {
      best_distance = d;
      best = c;
    }
  }
  // Plausible typo: at most a third of the word wrong (at least 1, at most 3 edits), or the
  // word is a prefix/extension of the key ("diam" for "diameter").
  const size_t allowed = std::min<size_t>(3, std::max<size_t>(1, word.size() / 3));
  if (best_distance <= allowed)
    return best;
  for (const auto &c : candidates)
    if (word.size() >= 3 && (lower(c).rfind(lower(word), 0) == 0 || lower(word).rfind(lower(c), 0) == 0))
      return c;
  return "";
}

std::string KeySpec::type_description() const
{
  switch (type)
  {
  case KeyType::section: return "section";
  case KeyType::list: return "list";
  case KeyType::map: return "map of name -> section";
  case KeyType::quantity:
    return dimension == Dimension::dimensionless ? "number"
                                                 : without_article(dimension_description(dimension)) + " [" + si_unit(dimension) + "]";
  case KeyType::integer: return "integer";
  case KeyType::boolean: return "true/false";
  case KeyType::string: return "text";
  case KeyType::choice:
  {
    std::string s = "one of:";
    for (size_t i = 0; i < choices.size(); ++i)
      s += (i ? ", " : " ") + choices[i];
    return s;
  }
  case KeyType::vector3:
    return "[x, y, z]" + (dimension == Dimension::dimensionless ? std::string() : " of " + without_article(dimension_description(dimension)) + "s");
  case KeyType::polygon: return "polygon [[x, y], ...] of lengths";
  case KeyType::box: return "box [[x, y, z], [x, y, z]] of lengths";
  }
  return "";
}

std::string KeySpec::range_description() const
{
  auto bound = [&](double v) {
    return type == KeyType::integer ? std::to_string(static_cast<long long>(std::llround(v)))
                                    : format_bound(v, dimension);
  };
  if (min && max)
    return std::string("in ") + (min_inclusive ? "[" : "(") + bound(*min) + ", " + bound(*max) +
           (max_inclusive ? "]" : ")");
  if (min)
    return (min_inclusive ? ">= " : "> ") + bound(*min);
  if (max)
    return (max_inclusive ? "<= " : "< ") + bound(*max);
  return "";
}

} // namespace magbrush
