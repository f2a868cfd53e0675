// A developer in a box (carriers 35 um +- 10 %, counter-charged, 150 of them; toner 7 um +- 1 um
// at 5 % concentration, -30 uC/g), periodic along x and y (1 mm), without a drum: the case text
// the toner-placement and validation tests vary by the toner's own keys (`toner_where`: where
// it goes and how, e.g. "attached: true").
#pragma once

#include <string>

namespace magbrush::testing {

inline std::string box_developer(const std::string &toner_where)
{
  return R"(
name: developer
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, friction: 0.45, damping: 0.6}
  toner: {youngs_modulus: 3e3 MPa, poisson_ratio: 0.35, density: 1100 kg/m^3, friction: 0.3, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
planes:
  - {name: floor, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
populations:
  - {name: carrier, kind: carrier, diameter: 35 um, diameter_std: 3.5 um, count: 150, counter_charge: true, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 0.3 mm]]}
  - {name: toner, kind: toner, diameter: 7 um, diameter_std: 1 um, concentration: 5 %, charge_to_mass: -30 uC/g, )" +
         toner_where + R"(}
dem: {gravity: [0, 0, 0], periodic_length_x: 1 mm, periodic_length_y: 1 mm}
)";
}

} // namespace magbrush::testing
