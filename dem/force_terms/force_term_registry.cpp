#include "dem/force_terms/force_term_registry.h"

#include "dem/dem_system.h"

#include <algorithm>
#include <stdexcept>

namespace magbrush::dem {

namespace {
// Function-local static: safe to use from other translation units' static initialisers.
std::vector<ForceTermFactory> &table()
{
  static std::vector<ForceTermFactory> factories;
  return factories;
}
} // namespace

bool register_force_term(const ForceTermFactory &factory)
{
  table().push_back(factory);
  return true;
}

std::vector<ForceTermFactory> force_term_factories()
{
  std::vector<ForceTermFactory> sorted = table();
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const ForceTermFactory &a, const ForceTermFactory &b) { return a.order < b.order; });
  return sorted;
}

std::vector<ForceTermChoice> add_case_force_terms(DemSystem &system, const Case &c)
{
  // The terms register from an OBJECT library: a program that links only magbrush_dem would
  // silently run without gravity, drag or magnetics. Refuse that instead.
  if (table().empty())
    throw std::logic_error("dem: no force term is registered: link the program with magbrush_force_terms "
                           "(dem/force_terms/CMakeLists.txt)");
  std::vector<ForceTermChoice> choices;
  for (const ForceTermFactory &f : force_term_factories())
  {
    ForceTermChoice choice{f.name, false, f.not_needed_because(c)};
    if (choice.reason.empty())
    {
      system.add_force_term(f.make(c, system));
      choice.on = true;
    }
    choices.push_back(choice);
  }
  return choices;
}

} // namespace magbrush::dem
