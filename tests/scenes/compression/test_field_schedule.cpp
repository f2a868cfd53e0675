// The piecewise-linear schedule of the uniform applied field (applied_field.schedule), used by
// Kawamoto's field sweep at a held plate: values between and outside the samples, the parsed
// case, and the errors for inconsistent input.
#include "fields/applied_magnetic_field.h"
#include "case/case_format.h"
#include "case/case_parser.h"

#include <gtest/gtest.h>

#include <string>

using namespace magbrush;

namespace {
const std::string box_with = R"(scene: box
planes:
  - {name: stage, point: [0, 0, 0], normal: [0, 0, 1]}
materials:
  carrier: {youngs_modulus: 1e3 MPa, density: 2200 kg/m^3, mu_r: 3.9}
  wall: {youngs_modulus: 5e4 MPa}
populations:
  - {name: carrier, diameter: 60 um, count: 10, insert_box: [[0, 0, 0], [1 mm, 1 mm, 1 mm]]}
dem: {periodic_length_x: 1 mm, periodic_length_y: 1 mm, duration: 1 ms}
applied_field:
  kind: uniform
  direction: [0, 0, 1]
)";

std::string error_of(const std::string &text, const std::vector<std::string> &overrides = {})
{
  try
  {
    parse_case_text(text, "t.yaml", overrides);
  }
  catch (const CaseError &e)
  {
    return e.what();
  }
  return "";
}
} // namespace

TEST(FieldSchedule, PiecewiseLinearAndHeldOutside)
{
  const AppliedMagneticField f =
      AppliedMagneticField::uniform_schedule({0, 0, 2}, {{1e-3, 0.0}, {2e-3, 0.13}, {3e-3, 0.13}, {3.5e-3, 0.03}});
  auto bz = [&](double t) { return f.field({0, 0, 0}, t)[2]; };
  EXPECT_DOUBLE_EQ(bz(0.0), 0.0); // before the first sample: its value
  EXPECT_DOUBLE_EQ(bz(1e-3), 0.0);
  EXPECT_NEAR(bz(1.5e-3), 0.065, 1e-15); // linear
  EXPECT_NEAR(bz(2.5e-3), 0.13, 1e-15);  // hold
  EXPECT_NEAR(bz(3.25e-3), 0.08, 1e-15); // linear down
  EXPECT_NEAR(bz(10e-3), 0.03, 1e-15);   // after the last: held
  EXPECT_DOUBLE_EQ(f.field({0, 0, 0}, 2.2e-3)[0], 0.0);
  // A single sample is a constant field.
  EXPECT_NEAR(AppliedMagneticField::uniform_schedule({1, 0, 0}, {{0.0, 0.05}}).field({0, 0, 0}, 1.0)[0], 0.05, 1e-15);
  EXPECT_THROW(AppliedMagneticField::uniform_schedule({0, 0, 1}, {{1e-3, 0.1}, {1e-3, 0.2}}), std::invalid_argument);
  EXPECT_THROW(AppliedMagneticField::uniform_schedule({0, 0, 1}, {{0.0, 0.0}}), std::invalid_argument);
  EXPECT_THROW(AppliedMagneticField::uniform_schedule({0, 0, 1}, {{0.0, -0.1}}), std::invalid_argument);
}

TEST(FieldSchedule, ParsedFromTheCaseWithUnits)
{
  const Case c = parse_case_text(box_with + "  schedule:\n"
                                            "    - {time: 0 ms, magnitude: 0 mT}\n"
                                            "    - {time: 1 ms, magnitude: 130 mT}\n"
                                            "    - {time: 2 ms, magnitude: 40 mT}\n",
                                 "t.yaml");
  ASSERT_EQ(c.applied_field.schedule.size(), 3u);
  EXPECT_DOUBLE_EQ(c.applied_field.schedule[1].first, 1e-3);
  EXPECT_DOUBLE_EQ(c.applied_field.schedule[1].second, 0.13);
  EXPECT_DOUBLE_EQ(c.applied_field.uniform_magnitude, 0.13); // the peak
  const AppliedMagneticField f = AppliedMagneticField::from_settings(c.applied_field);
  EXPECT_NEAR(f.field({0, 0, 0}, 1.5e-3)[2], 0.085, 1e-15);
  // The printed case reads back (the schedule is printed instead of magnitude/ramp_time).
  std::vector<std::string> overrides;
  for (const auto &e : resolved_entries(c))
    overrides.push_back(e.path + "=" + e.pretty);
  const Case again = parse_case_text(box_with + "  schedule:\n"
                                                "    - {time: 0 ms, magnitude: 0 mT}\n"
                                                "    - {time: 1 ms, magnitude: 130 mT}\n"
                                                "    - {time: 2 ms, magnitude: 40 mT}\n",
                                     "t.yaml", overrides);
  EXPECT_EQ(again.applied_field.schedule, c.applied_field.schedule);
  // The whole schedule can be replaced from the command line.
  const Case swept =
      parse_case_text(box_with + "  magnitude: 130 mT\n", "t.yaml",
                      {"applied_field.magnitude=0 mT",
                       "applied_field.schedule=[{time: 0 s, magnitude: 20 mT}, {time: 1 ms, magnitude: 60 mT}]"});
  EXPECT_DOUBLE_EQ(swept.applied_field.uniform_magnitude, 0.06);
}

TEST(FieldSchedule, InconsistentInputIsRefusedWithTheKey)
{
  const std::string both =
      error_of(box_with + "  magnitude: 130 mT\n  schedule:\n    - {time: 0 s, magnitude: 1 mT}\n");
  EXPECT_NE(both.find("applied_field.magnitude: give either a schedule or magnitude"), std::string::npos) << both;
  const std::string order = error_of(box_with + "  schedule:\n    - {time: 1 ms, magnitude: 1 mT}\n"
                                                "    - {time: 0.5 ms, magnitude: 2 mT}\n");
  EXPECT_NE(order.find("applied_field.schedule[1].time: schedule times must increase"), std::string::npos) << order;
  const std::string zero = error_of(box_with + "  schedule:\n    - {time: 0 s, magnitude: 0 mT}\n");
  EXPECT_NE(zero.find("at least one magnitude > 0"), std::string::npos) << zero;
  const std::string unit = error_of(box_with + "  schedule:\n    - {time: 0 s, magnitude: 3 mm}\n");
  EXPECT_NE(unit.find("magnetic flux density"), std::string::npos) << unit;
}
