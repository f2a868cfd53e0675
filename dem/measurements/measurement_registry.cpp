#include "dem/measurements/measurement_registry.h"

#include "dem/dem_run.h"

namespace magbrush::dem {

namespace {
// Function-local static: safe to use from other translation units' static initialisers.
std::vector<MeasurementFactory> &table()
{
  static std::vector<MeasurementFactory> factories;
  return factories;
}
} // namespace

bool register_measurement(const MeasurementFactory &factory)
{
  table().push_back(factory);
  return true;
}

const std::vector<MeasurementFactory> &measurement_factories() { return table(); }

std::vector<std::string> add_case_measurements(DemRun &run, const Case &c)
{
  std::vector<std::string> names;
  for (const auto &f : table())
    if (auto m = f.make(c))
    {
      names.push_back(m->name());
      run.add_measurement(std::move(m));
    }
  return names;
}

} // namespace magbrush::dem
