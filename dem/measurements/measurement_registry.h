// Which measurements a run takes is decided by the scene: a nip scene gets the profiles along
// the gap, a compression scene the plate forces. Each measurement lives in its own file in
// dem/measurements/ and registers a factory at start-up (like the driver's subcommands):
//
//   static const bool registered = magbrush::dem::register_measurement(
//       {"nip_profile", [](const Case &c) -> std::unique_ptr<Measurement> {
//          if (!applies(c)) return nullptr;
//          return std::make_unique<NipProfile>(c); }});
//
// so adding one never touches dem_main.cpp. The library is an OBJECT library so that the
// linker keeps every registration.
#pragma once

#include "dem/measurement.h"

#include "case/case_model.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace magbrush::dem {

class DemRun;

struct MeasurementFactory
{
  std::string name;
  // Returns the measurement for this case, or nullptr when the scene does not call for it.
  std::function<std::unique_ptr<Measurement>(const Case &)> make;
};

bool register_measurement(const MeasurementFactory &factory);
const std::vector<MeasurementFactory> &measurement_factories();

// Adds to `run` every registered measurement that applies to case `c`; returns their names.
std::vector<std::string> add_case_measurements(DemRun &run, const Case &c);

} // namespace magbrush::dem
