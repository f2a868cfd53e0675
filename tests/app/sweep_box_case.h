// The small scene of the sweep tests (tests/app/test_sweep*.cpp): 100 carriers of 100 um
// falling onto a plate in a periodic 1 x 1 mm box for 20 us, DEM only — a two-point sweep of
// it takes seconds.
#pragma once

namespace magbrush::testing {

inline const char *const sweep_box_case = R"(name: sweep_box
scene: box
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
materials:
  carrier: {youngs_modulus: 100 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 100 um, count: 100, insert_box: [[0 mm, 0 mm, 0.05 mm], [1 mm, 1 mm, 1 mm]]}
dem: {duration: 20 us, output_interval: 10 us, periodic_length_x: 1 mm, periodic_length_y: 1 mm, gravity: [0, 0, -9.81 m/s^2]}
)";

} // namespace magbrush::testing
