// Units: every unit symbol, SI prefixes, µ/μ/u, exponents, bare numbers refused, dimension
// mismatches, garbage, and format_quantity <-> parse_quantity round trips.
#include "case/units.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace magbrush;

namespace {
constexpr double pi = 3.14159265358979323846;

void expect_si(const std::string &text, Dimension d, double si)
{
  SCOPED_TRACE(text);
  EXPECT_NEAR(parse_quantity(text, d), si, 1e-12 * std::abs(si)) << text;
}

std::string error_of(const std::string &text, Dimension d)
{
  try
  {
    parse_quantity(text, d);
  }
  catch (const UnitError &e)
  {
    return e.what();
  }
  return "(no error)";
}
} // namespace

TEST(Units, Lengths)
{
  expect_si("25 mm", Dimension::length, 0.025);
  expect_si("1 m", Dimension::length, 1.0);
  expect_si("60 um", Dimension::length, 60e-6);
  expect_si("60 µm", Dimension::length, 60e-6);      // micro sign U+00B5
  expect_si("60 \xCE\xBCm", Dimension::length, 60e-6); // Greek mu U+03BC
  expect_si("400 nm", Dimension::length, 400e-9);
  expect_si("2.5 cm", Dimension::length, 0.025);
  expect_si("1.2 km", Dimension::length, 1200.0);
  expect_si("25mm", Dimension::length, 0.025);
  expect_si("  25   mm  ", Dimension::length, 0.025);
}

TEST(Units, TimesAnglesSpeeds)
{
  expect_si("2e-8 s", Dimension::time, 2e-8);
  expect_si("20 ns", Dimension::time, 20e-9);
  expect_si("5 us", Dimension::time, 5e-6);
  expect_si("5 µs", Dimension::time, 5e-6);
  expect_si("3 ms", Dimension::time, 3e-3);
  expect_si("2 min", Dimension::time, 120.0);
  expect_si("1 h", Dimension::time, 3600.0);
  expect_si("90 deg", Dimension::angle, pi / 2);
  expect_si("90°", Dimension::angle, pi / 2);
  expect_si("1.5 rad", Dimension::angle, 1.5);
  expect_si("20 mrad", Dimension::angle, 0.02);
  expect_si("1 rev", Dimension::angle, 2 * pi);
  expect_si("219 rpm", Dimension::angular_velocity, 219 * 2 * pi / 60);
  expect_si("-29 rpm", Dimension::angular_velocity, -29 * 2 * pi / 60);
  expect_si("10 rad/s", Dimension::angular_velocity, 10.0);
  expect_si("360 deg/s", Dimension::angular_velocity, 2 * pi);
  expect_si("50 Hz", Dimension::frequency, 50.0);
  expect_si("2 kHz", Dimension::frequency, 2000.0);
  expect_si("3 /s", Dimension::frequency, 3.0);
}

TEST(Units, Electromagnetic)
{
  expect_si("130 mT", Dimension::magnetic_flux_density, 0.13);
  expect_si("1.2 T", Dimension::magnetic_flux_density, 1.2);
  expect_si("1000 G", Dimension::magnetic_flux_density, 0.1); // gauss
  expect_si("1.3 kG", Dimension::magnetic_flux_density, 0.13);
  expect_si("172 kA/m", Dimension::magnetisation, 172e3);
  expect_si("1.1 MA/m", Dimension::magnetisation, 1.1e6);
  expect_si("-600 V", Dimension::voltage, -600.0);
  expect_si("1.5 kV", Dimension::voltage, 1500.0);
  expect_si("-30 uC/g", Dimension::charge_to_mass, -30e-3);
  expect_si("-30 µC/g", Dimension::charge_to_mass, -30e-3);
  expect_si("-0.03 C/kg", Dimension::charge_to_mass, -0.03);
  expect_si("-100 uC/m^2", Dimension::surface_charge, -1e-4);
  expect_si("1e-4 C/m^2", Dimension::surface_charge, 1e-4);
  expect_si("40 mg/cm^2", Dimension::areal_mass, 0.4);
  expect_si("500 g/m", Dimension::linear_mass, 0.5);
  expect_si("-5 fC", Dimension::charge, -5e-15);
  expect_si("2 kV/mm", Dimension::electric_field, 2e6);
  expect_si("3 MV/m", Dimension::electric_field, 3e6);
}

TEST(Units, Mechanical)
{
  expect_si("1e3 MPa", Dimension::pressure, 1e9);
  expect_si("5e4 MPa", Dimension::pressure, 5e10);
  expect_si("50 GPa", Dimension::pressure, 5e10);
  expect_si("3 kPa", Dimension::pressure, 3e3);
  expect_si("7 Pa", Dimension::pressure, 7.0);
  expect_si("2200 kg/m^3", Dimension::density, 2200.0);
  expect_si("4.8 g/cm^3", Dimension::density, 4800.0);
  expect_si("4.8 g/cm³", Dimension::density, 4800.0);
  expect_si("1.81e-5 Pa*s", Dimension::viscosity, 1.81e-5);
  expect_si("1.81e-5 Pa s", Dimension::viscosity, 1.81e-5);
  expect_si("18.1 uPa·s", Dimension::viscosity, 1.81e-5);
  expect_si("1e-19 J", Dimension::energy, 1e-19);
  expect_si("0.1 m/s", Dimension::velocity, 0.1);
  expect_si("100 mm/s", Dimension::velocity, 0.1);
  expect_si("2 kg", Dimension::mass, 2.0);
  expect_si("2 g", Dimension::mass, 2e-3);
  expect_si("50 mg", Dimension::mass, 50e-6);
  expect_si("-9.81 m/s^2", Dimension::acceleration, -9.81);
  expect_si("-9.81 m/s/s", Dimension::acceleration, -9.81);
  expect_si("-9.81 m*s^-2", Dimension::acceleration, -9.81);
  expect_si("-9.81 m s^-2", Dimension::acceleration, -9.81);
  expect_si("-9.81 m/s²", Dimension::acceleration, -9.81);
  expect_si("1 mN", Dimension::force, 1e-3);
  expect_si("1 kg*m/s^2", Dimension::force, 1.0);
  expect_si("10 rad^-2", Dimension::inverse_angle_squared, 10.0);
}

TEST(Units, BareNumbersAreRefusedWithAUnitSuggested)
{
  // A dimensional quantity needs its unit: a bare number is an error naming the dimension and
  // the unit its magnitude suggests.
  EXPECT_NE(error_of("0.3", Dimension::length).find("0.3 \u2014 a length needs a unit: 0.3 mm?"), std::string::npos)
      << error_of("0.3", Dimension::length);
  EXPECT_NE(error_of("300", Dimension::length).find("300 um?"), std::string::npos);
  EXPECT_NE(error_of("90", Dimension::angle).find("an angle needs a unit: 90 deg?"), std::string::npos);
  EXPECT_NE(error_of("1.5708", Dimension::angle).find("needs a unit: 1.5708 rad"), std::string::npos);
  EXPECT_NE(error_of("-600", Dimension::voltage).find("-600 V?"), std::string::npos);
  EXPECT_NE(error_of("219", Dimension::angular_velocity).find("needs a unit: 219 rpm"), std::string::npos);
  EXPECT_NE(error_of("+2.5e-3", Dimension::time).find("a time needs a unit"), std::string::npos);
  EXPECT_NE(error_of("10", Dimension::inverse_angle_squared).find("10 rad^-2?"), std::string::npos);
  EXPECT_NE(error_of("0.3", Dimension::length).find("a bare number is not read as SI"), std::string::npos);
  // As plausible in two units: both are offered.
  EXPECT_NE(error_of("60", Dimension::length).find("60 um or 60 mm?"), std::string::npos) << error_of("60", Dimension::length);
  // A bare zero is zero in every unit: accepted.
  expect_si("0", Dimension::length, 0.0);
  expect_si("0.0", Dimension::angle, 0.0);
  expect_si("-0", Dimension::voltage, 0.0);
  expect_si("0e3", Dimension::time, 0.0);
  // Plain numbers stay bare.
  expect_si(".5", Dimension::dimensionless, 0.5);
  expect_si("7 %", Dimension::dimensionless, 0.07);
  // Where a caller reads data documented as SI, bare numbers are SI.
  EXPECT_DOUBLE_EQ(parse_quantity("0.025", Dimension::length, BareNumber::si), 0.025);
  EXPECT_DOUBLE_EQ(parse_quantity("1.5", Dimension::angle, BareNumber::si), 1.5);
}

TEST(Units, LikelyUnitsFollowTheTypicalScale)
{
  EXPECT_EQ(likely_units(0.3, Dimension::length), std::vector<std::string>{"mm"});
  EXPECT_EQ(likely_units(300, Dimension::length), std::vector<std::string>{"um"});
  EXPECT_EQ(likely_units(90, Dimension::angle), std::vector<std::string>{"deg"});
  // A key's own scale (its default) decides: a time step of 2e-8 is in seconds.
  EXPECT_EQ(likely_units(2e-8, Dimension::time, 40e-9).front(), "s");
  EXPECT_EQ(likely_units(40, Dimension::time, 40e-9).front(), "ns");
  // A Young's modulus written in SI.
  EXPECT_EQ(likely_units(1e9, Dimension::pressure, 1e9).front(), "Pa");
}

TEST(Units, DimensionMismatchSaysBoth)
{
  const std::string e = error_of("219 rpm", Dimension::length);
  EXPECT_NE(e.find("expected a length (e.g. 25 mm)"), std::string::npos) << e;
  EXPECT_NE(e.find("found '219 rpm'"), std::string::npos) << e;
  EXPECT_NE(e.find("angular velocity"), std::string::npos) << e;
  EXPECT_NE(error_of("130 mT", Dimension::magnetisation).find("magnetic flux density"), std::string::npos);
  EXPECT_NE(error_of("5 mm", Dimension::dimensionless).find("that is a length"), std::string::npos);
  EXPECT_NE(error_of("90 deg", Dimension::dimensionless).find("an angle"), std::string::npos);
  // Hz and rad/s are different dimensions (angles are tracked).
  EXPECT_NE(error_of("50 Hz", Dimension::angular_velocity).find("frequency"), std::string::npos);
  // No named dimension: the exponents are spelt out.
  EXPECT_NE(error_of("3 m^4", Dimension::length).find("units of m^4"), std::string::npos);
}

TEST(Units, GarbageIsRejectedWithAReason)
{
  for (const char *text : {"", "   ", "mm", "abc", "inf", "nan", "-inf mm", "0x10", "1e999", "5 furlongs",
                           "5 m/", "5 */m", "5 m//s", "5 m^", "5 m^x", "5 m^999", "5 mm extra!", "5 m$",
                           "five mm", "1,5 mm", "5 Mm m m m m^-4 x"})
  {
    SCOPED_TRACE(text);
    const std::string e = error_of(text, Dimension::length);
    EXPECT_EQ(e.rfind("expected a length", 0), 0u) << e;
    EXPECT_NE(e.find(std::string("found '") + text + "'"), std::string::npos) << e;
  }
  EXPECT_NE(error_of("5 furlongs", Dimension::length).find("unknown unit 'furlongs'"), std::string::npos);
  EXPECT_NE(error_of("", Dimension::length).find("empty"), std::string::npos);
}

TEST(Units, FormatUsesTheUnitsUsersWrite)
{
  EXPECT_EQ(format_quantity(0.025, Dimension::length), "25 mm");
  EXPECT_EQ(format_quantity(400e-6, Dimension::length), "400 um");
  EXPECT_EQ(format_quantity(219 * 2 * pi / 60, Dimension::angular_velocity), "219 rpm");
  EXPECT_EQ(format_quantity(0.13, Dimension::magnetic_flux_density), "130 mT");
  EXPECT_EQ(format_quantity(172e3, Dimension::magnetisation), "172 kA/m");
  EXPECT_EQ(format_quantity(-600.0, Dimension::voltage), "-600 V");
  EXPECT_EQ(format_quantity(1e9, Dimension::pressure), "1000 MPa");
  EXPECT_EQ(format_quantity(-0.03, Dimension::charge_to_mass), "-30 uC/g");
  EXPECT_EQ(format_quantity(2e-8, Dimension::time), "20 ns");
  EXPECT_EQ(format_quantity(pi / 2, Dimension::angle), "90 deg");
  EXPECT_EQ(format_quantity(0.0, Dimension::length), "0 mm");
  EXPECT_EQ(format_quantity(0.35, Dimension::dimensionless), "0.35");
}

TEST(Units, FormatThenParseRoundTrips)
{
  const Dimension all[] = {Dimension::dimensionless, Dimension::length, Dimension::time, Dimension::angle,
                           Dimension::angular_velocity, Dimension::magnetic_flux_density,
                           Dimension::magnetisation, Dimension::voltage, Dimension::pressure,
                           Dimension::density, Dimension::charge_to_mass, Dimension::surface_charge,
                           Dimension::viscosity, Dimension::energy, Dimension::velocity, Dimension::mass,
                           Dimension::acceleration, Dimension::frequency, Dimension::charge, Dimension::force,
                           Dimension::electric_field, Dimension::inverse_angle_squared, Dimension::areal_mass,
                           Dimension::linear_mass};
  for (Dimension d : all)
    for (double v : {1.234567e-12, -3.3e-7, 4.2e-4, 0.5, 1.0, 73.21, -2.5e3, 6.02e5, 1.7e9, 0.0})
    {
      const std::string text = format_quantity(v, d);
      SCOPED_TRACE(text);
      EXPECT_NEAR(parse_quantity(text, d), v, 5e-6 * std::abs(v)) << dimension_description(d); // 6 digits
      // the example quoted in error messages parses too
      EXPECT_NO_THROW(parse_quantity(dimension_example(d), d)) << dimension_example(d);
    }
}

TEST(Units, LongInputsAreShortenedInMessages)
{
  const std::string blob(100000, 'x');
  const std::string e = error_of("5 " + blob, Dimension::length);
  EXPECT_LT(e.size(), 400u);
  EXPECT_NE(e.find("100002 characters"), std::string::npos) << e;
}
