// The measurement registry: a factory registered at start-up is asked for every case and its
// measurement is added to the run only when the scene calls for it.
#include "dem/measurements/measurement_registry.h"

#include "dem/dem_run.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <filesystem>
#include <sstream>

using namespace magbrush;
using namespace magbrush::dem;

namespace {
class NullMeasurement : public Measurement
{
public:
  const char *name() const override { return "null probe"; }
  double interval() const override { return 0.0; }
  void sample(const DemSystem &) override {}
  void write(const std::string &) const override {}
  void write_state(StateOut &) const override {}
  void read_state(StateIn &) override {}
};

// Applies only to cases named "wants_probe".
const bool registered = register_measurement(
    {"null probe", [](const Case &c) -> std::unique_ptr<Measurement> {
       if (c.name != "wants_probe")
         return nullptr;
       return std::make_unique<NullMeasurement>();
     }});

Case tiny_case(const std::string &name)
{
  Case c;
  c.name = name;
  c.source_file = "(test)";
  c.scene = "box";
  Material m;
  m.name = "m";
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  m.density = 2000;
  c.materials.push_back(m);
  c.dem.gravity = {0, 0, 0};
  return c;
}
} // namespace

TEST(MeasurementRegistry, AddsOnlyTheMeasurementsAScenesCallsFor)
{
  ASSERT_TRUE(registered);
  bool listed = false;
  for (const auto &f : measurement_factories())
    listed = listed || f.name == "null probe";
  EXPECT_TRUE(listed);
  RunOptions o;
  o.output_dir = (magbrush::testing::test_temp_dir("registry") / "out").string();
  std::ostringstream log;
  for (const std::string name : {"wants_probe", "other"})
  {
    const Case c = tiny_case(name);
    DemRun run(c, o, log);
    const auto added = add_case_measurements(run, c);
    const bool has = std::find(added.begin(), added.end(), "null probe") != added.end();
    EXPECT_EQ(has, name == "wants_probe") << name;
    EXPECT_EQ(run.measurements().size(), added.size());
  }
  std::filesystem::remove_all(o.output_dir);
}
