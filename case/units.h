// Physical quantities in case files: "25 mm", "219 rpm", "130 mT", "-600 V", "1e3 MPa".
//
// A quantity is a number followed by a unit expression. The expression is a product of unit
// symbols, each with an optional SI prefix and an optional integer exponent, joined by '*',
// '·', a space or '/': "kg/m^3", "uC/g", "Pa*s", "m/s^2", "kA/m". Units are checked by
// dimensional analysis, so "uC/g" and "C/kg" are the same dimension and "219 rpm" where a
// length is expected is an error that says both.
//
// A dimensional quantity needs its unit: a bare number is refused with a suggestion from its
// magnitude ("0.3 — a length needs a unit: 0.3 mm?"), because the unit a user had in mind
// cannot be known ("0.3" for a gap is 0.3 mm, not 0.3 m). The one exception is a bare 0 (also
// written 0.0, -0, 0e5): zero is zero in every unit of the dimension, since all units here
// are multiples of the SI unit. Plain numbers (Dimension::dimensionless) are bare by nature.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {

struct UnitError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

// The physical dimensions case keys can have. Angles are kept as their own dimension
// (radian), so "90 deg" is never accepted as a plain number and vice versa.
enum class Dimension
{
  dimensionless,
  length,
  time,
  angle,
  angular_velocity,      // rpm, rad/s
  magnetic_flux_density, // T, mT, G
  magnetisation,         // A/m, kA/m
  voltage,               // V, kV
  pressure,              // Pa, MPa (also Young's moduli)
  density,               // kg/m^3, g/cm^3
  charge_to_mass,        // C/kg, uC/g
  surface_charge,        // C/m^2, uC/m^2
  viscosity,             // Pa*s
  energy,                // J (Hamaker constants)
  velocity,              // m/s
  mass,                  // kg, g, mg
  acceleration,          // m/s^2
  frequency,             // Hz, 1/s
  charge,                // C, fC
  force,                 // N
  electric_field,        // V/m, kV/mm
  inverse_angle_squared, // 1/rad^2 (Gaussian pole shape factor)
  areal_mass,            // kg/m^2, mg/cm^2 (developer mass per sleeve area, DMA)
  linear_mass,           // kg/m, g/mm (mass per length along the roller axis: the sump)
};

// How a bare number (no unit) is read where a dimensional quantity is expected.
enum class BareNumber
{
  refused, // an error suggesting a unit, except for 0 (case files, --set, command-line options)
  si,      // taken as SI (data columns documented as "in SI or with units")
};

// Converts "25 mm" to 0.025 (SI). Throws UnitError naming what was expected and found,
// e.g. "expected a length (e.g. 25 mm), found '219 rpm' (an angular velocity)".
// A refused bare number throws UnitError("0.3 — a length needs a unit: 0.3 mm? ..."); the
// unit suggested is the one that puts the number nearest `typical_si` (0: the dimension's
// usual scale in this code, e.g. 1 mm for a length; likely_units()).
double parse_quantity(const std::string &text, Dimension expected, BareNumber bare = BareNumber::refused,
                      double typical_si = 0.0);

// The units a bare `number` most likely meant for dimension d, best first (one, or two when
// the number is as plausible in both): the usual units of the dimension, ranked by how close
// number x unit comes to `typical_si` on a log scale (0: the dimension's usual scale).
// "0.3" as a length -> {"mm"}; "60" -> {"um", "mm"}; "90" as an angle -> {"deg"}.
std::vector<std::string> likely_units(double number, Dimension d, double typical_si = 0.0);

// The value in the unit a user would write for this dimension ("25 mm", "219 rpm",
// "130 mT", "172 kA/m", "1000 MPa"), 6 significant digits.
std::string format_quantity(double si_value, Dimension d);

// "a length", "an angular velocity", ...
std::string dimension_description(Dimension d);
// A short example in the usual unit, e.g. "25 mm".
std::string dimension_example(Dimension d);
// The SI unit symbol, e.g. "m", "rad/s", "kg/m^3" ("" for dimensionless).
std::string si_unit(Dimension d);

} // namespace magbrush
