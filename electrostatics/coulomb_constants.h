// The vacuum permittivity and the Coulomb constant (CODATA 2018), shared by the electrostatic
// terms: the far field works in kernel units (Φ = Σ q/r), the physical field is
// E = coulomb_constant × (kernel field).
#pragma once

namespace magbrush::electrostatics {

constexpr double pi = 3.14159265358979323846;
constexpr double vacuum_permittivity = 8.8541878128e-12; // ε0 [F/m]
constexpr double coulomb_constant = 1.0 / (4.0 * pi * vacuum_permittivity); // 1/(4πε0) [m/F]

} // namespace magbrush::electrostatics
